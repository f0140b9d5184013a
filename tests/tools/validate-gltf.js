#!/usr/bin/env node
// Validates glTF 2.0 files with the Khronos glTF-Validator (npm package
// `gltf-validator`, its `validateBytes` API).
//
//   NODE_PATH=/path/to/node_modules node tests/tools/validate-gltf.js FILE...
//
// For each file prints one line
//   FILE: errors=N warnings=N infos=N hints=N
// followed by the first few messages (code, severity, pointer, message).
// Exit status: 0 when every file is free of errors, 1 when any file has
// errors, 2 when a file cannot be read or the validator cannot run.
// Used by tests/gltf.rs; see .ci/run for installing the validator.
'use strict';

const fs = require('fs');
const path = require('path');

const SEVERITY = ['error', 'warning', 'info', 'hint'];
const SHOWN = 10;

let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error(`cannot load gltf-validator (set NODE_PATH to its node_modules): ${e.message}`);
  process.exit(2);
}

// External resources (side-file buffers, images) are read next to the file.
function externalResourceFunction(dir) {
  return (uri) =>
    new Promise((resolve, reject) => {
      const target = path.resolve(dir, decodeURIComponent(uri));
      fs.readFile(target, (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
    });
}

async function validate(file) {
  let bytes;
  try {
    bytes = new Uint8Array(fs.readFileSync(file));
  } catch (e) {
    console.log(`${file}: unreadable: ${e.message}`);
    return 2;
  }
  let report;
  try {
    report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,
      externalResourceFunction: externalResourceFunction(path.dirname(file)),
    });
  } catch (e) {
    console.log(`${file}: unreadable: ${e}`);
    return 2;
  }
  const issues = report.issues;
  console.log(
    `${file}: errors=${issues.numErrors} warnings=${issues.numWarnings} ` +
      `infos=${issues.numInfos} hints=${issues.numHints}`
  );
  for (const m of issues.messages.slice(0, SHOWN)) {
    const where = m.pointer ? ` at ${m.pointer}` : m.offset !== undefined ? ` at byte ${m.offset}` : '';
    console.log(`  ${SEVERITY[m.severity] || m.severity} ${m.code}${where}: ${m.message}`);
  }
  if (issues.messages.length > SHOWN) {
    console.log(`  ... ${issues.messages.length - SHOWN} more`);
  }
  return issues.numErrors > 0 ? 1 : 0;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: validate-gltf.js FILE...');
    process.exit(2);
  }
  let status = 0;
  for (const f of files) {
    status = Math.max(status, await validate(f));
  }
  process.exit(status);
}

main().catch((e) => {
  console.error(`validator failed: ${e}`);
  process.exit(2);
});
