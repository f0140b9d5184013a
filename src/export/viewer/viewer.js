// brickwright's step viewer: a small WebGL renderer, orbit camera controls
// and the step-by-step interface. Reads the model from the JSON block with
// id "model" (see src/export/html.rs for its layout); loads nothing else.
"use strict";
(function () {
  var body = document.body;
  var errorBox = document.getElementById("error");

  function fail(message) {
    errorBox.textContent = message;
    errorBox.hidden = false;
    body.setAttribute("data-state", "error");
  }
  window.addEventListener("error", function (e) {
    fail("The viewer stopped: " + (e && e.message ? e.message : "unknown error"));
  });

  var model = JSON.parse(document.getElementById("model").textContent);
  var canvas = document.getElementById("view");
  var $ = function (id) { return document.getElementById(id); };
  var ui = {
    first: $("first"), prev: $("prev"), next: $("next"), last: $("last"),
    slider: $("slider"), label: $("label"), explode: $("explode"), reset: $("reset"),
    stepTitle: $("step-title"), stepParts: $("step-parts").tBodies[0],
    allParts: $("all-parts").tBodies[0], summary: $("summary"), footer: $("footer")
  };

  // ---------------------------------------------------------------- data

  function decode(b64) {
    var s = atob(b64), bytes = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
    return bytes.buffer;
  }
  function hexColor(hex) {
    return [1, 3, 5].map(function (k) { return parseInt(hex.substr(k, 2), 16) / 255; });
  }

  var steps = model.steps;
  var colors = model.colors.map(function (c) { return hexColor(c.rgb); });
  // Instances grouped by part type, in build order. For each step the
  // group's shown pieces are laid out in its instance buffer as four runs:
  // earlier pieces out of sight (drawn only from inside the model), the
  // other earlier pieces whose top is out of sight (drawn bare), the rest
  // of the earlier pieces (whole), and the current step's (whole,
  // highlighted). Each instance carries the faces out of sight as a bit
  // mask (bottom, +X, -X, +Z, -Z: src/export/sight.rs), folded away by the
  // vertex shader.
  var STRIDE = 19; // floats: rotation columns (9), position (3), explode offset (3), colour (3), mask (1)
  var groups = model.parts.map(function (part) {
    return { part: part, rows: [], source: null, data: null, runs: [0, 0, 0, 0] };
  });
  model.pieces.forEach(function (row) { groups[row[0]].rows.push(row); });
  groups.forEach(function (g) {
    g.source = new Float32Array(g.rows.length * STRIDE);
    g.data = new Float32Array(g.rows.length * STRIDE);
    g.rows.forEach(function (row, i) {
      var m = model.rotations[row[3]], c = colors[row[1]];
      // Columns of the row-major LDraw matrix.
      g.source.set([m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8],
        row[4], row[5], row[6], row[7], row[8], row[9], c[0], c[1], c[2], 0], i * STRIDE);
    });
  });
  // Lays out every group's instances for step s; faces left out only when
  // the model is assembled (the exploded view opens the gaps).
  function arrange(s, assembled) {
    groups.forEach(function (g) {
      var runs = [[], [], [], []], masks = [];
      g.rows.forEach(function (row, i) {
        if (row[2] > s) return;
        var mask = 0, out = assembled;
        for (var k = 0; k < 5; k++) {
          if (assembled && row[11 + k] > 0 && row[11 + k] <= s) mask += 1 << k;
          else out = false;
        }
        var bare = assembled && row[10] > 0 && row[10] <= s;
        runs[row[2] === s ? 3 : out && bare ? 0 : bare ? 1 : 2].push(i);
        masks[i] = mask;
      });
      var n = 0;
      runs.forEach(function (run, k) {
        run.forEach(function (i) {
          g.data.set(g.source.subarray(i * STRIDE, (i + 1) * STRIDE), n * STRIDE);
          g.data[n * STRIDE + 18] = masks[i];
          n++;
        });
        g.runs[k] = run.length;
      });
    });
    uploaded = false;
  }
  var uploaded = false;

  // The box (min, max) of every piece, assembled (e = 0) or exploded (e = 1).
  function bounds(e) {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    model.pieces.forEach(function (row) {
      var p = model.parts[row[0]], m = model.rotations[row[3]];
      for (var r = 0; r < 3; r++) {
        var c = row[4 + r] + e * row[7 + r], h = 0;
        for (var k = 0; k < 3; k++) {
          c += m[3 * r + k] * p.center[k];
          h += Math.abs(m[3 * r + k]) * p.half[k];
        }
        lo[r] = Math.min(lo[r], c - h);
        hi[r] = Math.max(hi[r], c + h);
      }
    });
    if (!isFinite(lo[0])) return { center: [0, 0, 0], radius: 100, lo: [0, 0, 0], hi: [0, 0, 0] };
    var center = [0, 1, 2].map(function (k) { return (lo[k] + hi[k]) / 2; });
    var radius = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2;
    return { center: center, radius: Math.max(radius, 20), lo: lo, hi: hi };
  }
  var layouts = [bounds(0), bounds(1)];

  // ---------------------------------------------------------------- maths

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function normalize(a) {
    var l = Math.hypot(a[0], a[1], a[2]) || 1;
    return [a[0] / l, a[1] / l, a[2] / l];
  }
  function lookAt(eye, target, up, out) {
    var z = normalize(sub(eye, target)), x = normalize(cross(up, z)), y = cross(z, x);
    out.set([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
    return out;
  }
  function perspective(fovy, aspect, near, far, out) {
    var f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    out.set([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1,
      0, 0, 2 * far * near * nf, 0]);
    return out;
  }
  function multiply(a, b, out) {
    for (var c = 0; c < 4; c++) {
      for (var r = 0; r < 4; r++) {
        var s = 0;
        for (var k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
        out[c * 4 + r] = s;
      }
    }
    return out;
  }
  function lerp(a, b, t) { return a + (b - a) * t; }
  function ease(t) { return t < 0.5 ? 2 * t * t : 1 - Math.pow(-2 * t + 2, 2) / 2; }

  // ---------------------------------------------------------------- camera

  var FOV = 35 * Math.PI / 180;
  var UP = [0, -1, 0]; // LDraw: -Y is up
  var camera = { target: [0, 0, 0], dist: 500, az: 45 * Math.PI / 180, el: 30 * Math.PI / 180 };

  function fitDistance(radius) {
    var aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight) || 1;
    var half = Math.min(FOV / 2, Math.atan(Math.tan(FOV / 2) * aspect));
    return radius / Math.sin(half) * 1.08;
  }
  function fitted(layout) {
    return { target: layout.center.slice(), dist: fitDistance(layout.radius) };
  }
  function toEye() {
    var c = Math.cos(camera.el);
    return [Math.sin(camera.az) * c, -Math.sin(camera.el), -Math.cos(camera.az) * c];
  }
  function eye() {
    var d = toEye();
    return [0, 1, 2].map(function (k) { return camera.target[k] + camera.dist * d[k]; });
  }
  function worldPerPixel() {
    return 2 * camera.dist * Math.tan(FOV / 2) / Math.max(1, canvas.clientHeight);
  }

  // ---------------------------------------------------------------- WebGL

  // A vertex on a face of the part's bounding box, with that face's
  // normal, belongs to the face (bottom, +X, -X, +Z, -Z: bits 0 to 4 of the
  // instance's mask); a masked face is folded to a point outside the view.
  var VERTEX = [
    "attribute vec3 aPos; attribute vec3 aNormal;",
    "attribute vec3 iR0; attribute vec3 iR1; attribute vec3 iR2;",
    "attribute vec3 iT; attribute vec3 iE; attribute vec4 iColor;",
    "uniform mat4 uViewProj; uniform float uExplode; uniform vec3 uCenter; uniform vec3 uHalf;",
    "uniform float uGrow; uniform float uMasking;",
    "varying vec3 vNormal; varying vec3 vColor; varying vec3 vWorld;",
    "float face() {",
    "  vec3 q = aPos - uCenter, e = uHalf - 0.01;",
    "  if (aNormal.y > 0.5 && q.y > e.y) return 1.0;",
    "  if (aNormal.x > 0.5 && q.x > e.x) return 2.0;",
    "  if (aNormal.x < -0.5 && q.x < -e.x) return 4.0;",
    "  if (aNormal.z > 0.5 && q.z > e.z) return 8.0;",
    "  if (aNormal.z < -0.5 && q.z < -e.z) return 16.0;",
    "  return 0.0;",
    "}",
    "void main() {",
    "  mat3 r = mat3(iR0, iR1, iR2);",
    "  vec3 p = aPos + sign(aPos - uCenter) * uGrow;",
    "  vec3 w = r * p + iT + uExplode * iE;",
    "  vNormal = r * aNormal; vColor = iColor.rgb; vWorld = w;",
    "  gl_Position = uViewProj * vec4(w, 1.0);",
    "  float bit = face();",
    "  if (uMasking > 0.5 && bit > 0.5 && mod(floor(iColor.a / bit), 2.0) > 0.5) {",
    "    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);",
    "  }",
    "}"
  ].join("\n");
  var FRAGMENT = [
    "precision mediump float;",
    "uniform vec3 uLight; uniform vec3 uEye; uniform vec3 uUp; uniform int uMode;",
    "uniform vec3 uHighlight;",
    "varying vec3 vNormal; varying vec3 vColor; varying vec3 vWorld;",
    "void main() {",
    "  if (uMode == 2) { gl_FragColor = vec4(uHighlight, 1.0); return; }",
    "  vec3 n = normalize(vNormal);",
    "  vec3 v = normalize(uEye - vWorld);",
    "  float diffuse = max(dot(n, uLight), 0.0);",
    "  float sky = 0.5 + 0.5 * dot(n, uUp);",
    "  vec3 c = vColor * (0.30 + 0.22 * sky + 0.58 * diffuse);",
    "  c += vec3(0.22) * pow(max(dot(reflect(-uLight, n), v), 0.0), 24.0);",
    "  if (uMode == 1) {",
    "    float rim = pow(1.0 - max(dot(n, v), 0.0), 2.0);",
    "    c = mix(c, uHighlight, 0.12 + 0.45 * rim);",
    "  }",
    "  gl_FragColor = vec4(c, 1.0);",
    "}"
  ].join("\n");
  var ATTRIBUTES = ["aPos", "aNormal", "iR0", "iR1", "iR2", "iT", "iE", "iColor"];
  var HIGHLIGHT = [1.0, 0.62, 0.0];
  var BACKGROUND = [0.933, 0.941, 0.953];

  var gl = null, draw = null, program = null, loc = {}, meshes = [];

  // A context that can be had without a major performance caveat (a GPU),
  // antialiased; else (a software renderer, where multisampling costs
  // most of the frame) one without antialiasing.
  function openContext() {
    var fast = { antialias: true, alpha: false, depth: true, powerPreference: "high-performance",
      failIfMajorPerformanceCaveat: true };
    var slow = { antialias: false, alpha: false, depth: true };
    var opts = [fast, slow];
    for (var k = 0; k < opts.length; k++) {
      var c = canvas.getContext("webgl2", opts[k]);
      if (c) return { gl: c, webgl2: true };
      c = canvas.getContext("webgl", opts[k]) || canvas.getContext("experimental-webgl", opts[k]);
      if (c) return { gl: c, webgl2: false };
    }
    return null;
  }

  function initGL() {
    var opened = openContext();
    gl = opened && opened.gl;
    if (opened && opened.webgl2) {
      draw = {
        divisor: function (i, d) { gl.vertexAttribDivisor(i, d); },
        elements: function (n, type, count) { gl.drawElementsInstanced(gl.TRIANGLES, n, type, 0, count); },
        index32: true
      };
    } else {
      var ext = gl && gl.getExtension("ANGLE_instanced_arrays");
      if (!ext) {
        gl = null;
        fail("The 3D view needs WebGL with instanced drawing, which this browser does not offer " +
          "(or has turned off); the parts lists still work.");
        return false;
      }
      draw = {
        divisor: function (i, d) { ext.vertexAttribDivisorANGLE(i, d); },
        elements: function (n, type, count) { ext.drawElementsInstancedANGLE(gl.TRIANGLES, n, type, 0, count); },
        index32: !!gl.getExtension("OES_element_index_uint")
      };
    }
    function shader(type, source) {
      var s = gl.createShader(type);
      gl.shaderSource(s, source);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS) && !gl.isContextLost()) {
        throw new Error("shader: " + gl.getShaderInfoLog(s));
      }
      return s;
    }
    program = gl.createProgram();
    gl.attachShader(program, shader(gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(program, shader(gl.FRAGMENT_SHADER, FRAGMENT));
    ATTRIBUTES.forEach(function (name, i) { gl.bindAttribLocation(program, i, name); });
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS) && !gl.isContextLost()) {
      throw new Error("shader program: " + gl.getProgramInfoLog(program));
    }
    ["uViewProj", "uExplode", "uCenter", "uHalf", "uGrow", "uMasking", "uLight", "uEye", "uUp",
      "uMode", "uHighlight"].forEach(function (name) { loc[name] = gl.getUniformLocation(program, name); });
    meshes = groups.map(function (g) {
      var p = g.part;
      if (p.index32 && !draw.index32) throw new Error("part " + p.id + " needs 32-bit indices");
      var buffer = function (target, data) {
        var b = gl.createBuffer();
        gl.bindBuffer(target, b);
        gl.bufferData(target, data, gl.STATIC_DRAW);
        return b;
      };
      var ints = function (b64) {
        return p.index32 ? new Uint32Array(decode(b64)) : new Uint16Array(decode(b64));
      };
      var triangles = function (b64) {
        var indices = ints(b64);
        return { buffer: buffer(gl.ELEMENT_ARRAY_BUFFER, indices), count: indices.length };
      };
      return {
        positions: buffer(gl.ARRAY_BUFFER, new Float32Array(decode(p.positions))),
        normals: buffer(gl.ARRAY_BUFFER, new Float32Array(decode(p.normals))),
        whole: triangles(p.indices),
        coarse: triangles(p.coarseIndices),
        bare: triangles(p.bareIndices),
        type: p.index32 ? gl.UNSIGNED_INT : gl.UNSIGNED_SHORT,
        instances: buffer(gl.ARRAY_BUFFER, g.data)
      };
    });
    uploaded = false;
    gl.enable(gl.DEPTH_TEST);
    gl.enable(gl.CULL_FACE);
    return true;
  }

  // Draws instances [from, to) of group i with one of its meshes ("whole",
  // "coarse" or "bare").
  function drawRange(i, from, to, mesh) {
    if (to <= from) return;
    var m = meshes[i], t = m[mesh];
    gl.bindBuffer(gl.ARRAY_BUFFER, m.positions);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, m.normals);
    gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, m.instances);
    for (var a = 0; a < 6; a++) {
      gl.vertexAttribPointer(2 + a, a < 5 ? 3 : 4, gl.FLOAT, false, STRIDE * 4, (from * STRIDE + 3 * a) * 4);
    }
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, t.buffer);
    draw.elements(t.count, m.type, to - from);
    state.triangles += t.count / 3 * (to - from);
  }

  var state = { step: 1, explode: 0, triangles: 0 };

  function resize() {
    var dpr = Math.min(window.devicePixelRatio || 1, 2);
    var w = Math.max(1, Math.round(canvas.clientWidth * dpr));
    var h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
  }

  // Whole pieces are drawn coarse when a stud, at the model's nearest
  // point, is narrower than this many pixels.
  var COARSE_STUD_PIXELS = 8;
  var STUD_DIAMETER = 12; // LDU
  var view = new Float32Array(16), proj = new Float32Array(16), viewProj = new Float32Array(16);

  // The distance from e to the box of a layout, 0 inside it.
  function distanceTo(layout, e) {
    var d = [0, 1, 2].map(function (k) {
      return Math.max(layout.lo[k] - e[k], 0, e[k] - layout.hi[k]);
    });
    return Math.hypot(d[0], d[1], d[2]);
  }

  function render() {
    resize();
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    var e = eye();
    var layout = layouts[state.explode > 0.5 ? 1 : 0];
    var reach = camera.dist + Math.hypot.apply(null, sub(camera.target, layout.center)) + layout.radius * 1.5;
    var near = Math.max(camera.dist - layout.radius * 1.5, reach / 2000, 0.5);
    lookAt(e, camera.target, UP, view);
    perspective(FOV, canvas.width / canvas.height, near, reach, proj);
    // A light from the upper left, fixed to the camera.
    var right = [view[0], view[4], view[8]], up = [view[1], view[5], view[9]], back = [view[2], view[6], view[10]];
    var light = normalize([0, 1, 2].map(function (k) { return -0.45 * right[k] + 0.75 * up[k] + 0.6 * back[k]; }));
    // From inside the model (a camera zoomed into it) the faces left out
    // would show: draw everything there.
    var gap = distanceTo(layout, e);
    var masking = state.explode === 0 && gap > 0 ? 1 : 0;
    var studPixels = STUD_DIAMETER * canvas.height / (2 * Math.max(gap, near) * Math.tan(FOV / 2));
    var whole = studPixels < COARSE_STUD_PIXELS ? "coarse" : "whole";
    gl.useProgram(program);
    gl.uniformMatrix4fv(loc.uViewProj, false, multiply(proj, view, viewProj));
    gl.uniform1f(loc.uExplode, state.explode);
    gl.uniform1f(loc.uMasking, masking);
    gl.uniform3fv(loc.uLight, light);
    gl.uniform3fv(loc.uEye, e);
    gl.uniform3fv(loc.uUp, UP);
    gl.uniform3fv(loc.uHighlight, HIGHLIGHT);
    gl.enableVertexAttribArray(0);
    gl.enableVertexAttribArray(1);
    for (var a = 2; a < 8; a++) {
      gl.enableVertexAttribArray(a);
      draw.divisor(a, 1);
    }
    if (!uploaded) {
      groups.forEach(function (g, i) {
        gl.bindBuffer(gl.ARRAY_BUFFER, meshes[i].instances);
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, g.data);
      });
      uploaded = true;
    }
    state.triangles = 0;
    // Earlier steps as built; the current step tinted, then outlined: the
    // back faces of a slightly grown copy, a rim wherever it shows.
    gl.uniform1f(loc.uGrow, 0);
    gl.uniform1i(loc.uMode, 0);
    var i, g, r;
    for (i = 0; i < groups.length; i++) {
      g = groups[i];
      r = g.runs;
      gl.uniform3fv(loc.uCenter, g.part.center);
      gl.uniform3fv(loc.uHalf, g.part.half);
      drawRange(i, masking ? r[0] : 0, r[0] + r[1], "bare");
      drawRange(i, r[0] + r[1], r[0] + r[1] + r[2], whole);
    }
    gl.uniform1i(loc.uMode, 1);
    for (i = 0; i < groups.length; i++) {
      g = groups[i];
      r = g.runs;
      gl.uniform3fv(loc.uCenter, g.part.center);
      gl.uniform3fv(loc.uHalf, g.part.half);
      drawRange(i, r[0] + r[1] + r[2], r[0] + r[1] + r[2] + r[3], whole);
    }
    gl.cullFace(gl.FRONT);
    gl.uniform1i(loc.uMode, 2);
    gl.uniform1f(loc.uMasking, 0);
    gl.uniform1f(loc.uGrow, Math.min(Math.max(2.2 * worldPerPixel(), 0.6), 8));
    for (i = 0; i < groups.length; i++) {
      g = groups[i];
      r = g.runs;
      gl.uniform3fv(loc.uCenter, g.part.center);
      drawRange(i, r[0] + r[1] + r[2], r[0] + r[1] + r[2] + r[3], whole);
    }
    gl.cullFace(gl.BACK);
    for (a = 2; a < 8; a++) draw.divisor(a, 0);
  }

  // ---------------------------------------------------------------- frames

  var pending = false, animation = null;
  function requestRender() {
    if (pending || !gl) return;
    pending = true;
    window.requestAnimationFrame(frame);
  }
  function frame(now) {
    pending = false;
    if (animation) {
      var t = Math.min(1, (now - (animation.start === null ? (animation.start = now) : animation.start)) / animation.ms);
      animation.apply(ease(t));
      if (t >= 1) animation = null;
      else requestRender();
    }
    if (gl.isContextLost()) return;
    render();
    if (body.getAttribute("data-state") === "loading") body.setAttribute("data-state", "ready");
  }
  function animate(ms, apply) {
    animation = { start: null, ms: ms, apply: apply };
    requestRender();
  }

  // ---------------------------------------------------------------- steps

  function partLabel(p) {
    var td = document.createElement("td");
    td.appendChild(document.createTextNode(p.name + " "));
    var id = document.createElement("span");
    id.className = "id";
    id.textContent = p.id;
    td.appendChild(id);
    return td;
  }
  function colorLabel(ci) {
    var td = document.createElement("td"), sw = document.createElement("span");
    sw.className = "swatch";
    sw.style.background = model.colors[ci].rgb;
    td.appendChild(sw);
    td.appendChild(document.createTextNode(model.colors[ci].name));
    return td;
  }
  function countCell(text) {
    var td = document.createElement("td");
    td.className = "n";
    td.textContent = text;
    return td;
  }
  // Counts by (part, colour) of pieces with from < step <= to, in part then colour order.
  function tally(from, to) {
    var counts = {};
    model.pieces.forEach(function (row) {
      if (row[2] > from && row[2] <= to) {
        var key = row[0] * 65536 + row[1];
        counts[key] = (counts[key] || 0) + 1;
      }
    });
    return counts;
  }
  var allCounts = tally(0, Infinity);
  var allKeys = Object.keys(allCounts).map(Number).sort(function (a, b) { return a - b; });
  var allRows = allKeys.map(function (key) {
    var tr = document.createElement("tr"), part = model.parts[Math.floor(key / 65536)];
    tr.appendChild(partLabel(part));
    tr.appendChild(colorLabel(key % 65536));
    tr.appendChild(countCell(""));
    ui.allParts.appendChild(tr);
    return tr;
  });

  function showStep() {
    var s = state.step, now = tally(s - 1, s), done = tally(0, s);
    var inStep = 0, placed = 0;
    Object.keys(now).forEach(function (k) { inStep += now[k]; });
    Object.keys(done).forEach(function (k) { placed += done[k]; });
    ui.slider.value = String(s);
    ui.label.textContent = steps ? "Step " + s + " of " + steps : "No steps";
    ui.stepTitle.textContent = steps
      ? "Step " + s + ": " + inStep + (inStep === 1 ? " piece" : " pieces")
      : "No pieces";
    ui.first.disabled = ui.prev.disabled = s <= 1;
    ui.next.disabled = ui.last.disabled = s >= steps;
    while (ui.stepParts.firstChild) ui.stepParts.removeChild(ui.stepParts.firstChild);
    allKeys.forEach(function (key, i) {
      if (now[key]) {
        var tr = document.createElement("tr");
        tr.appendChild(partLabel(model.parts[Math.floor(key / 65536)]));
        tr.appendChild(colorLabel(key % 65536));
        tr.appendChild(countCell(String(now[key])));
        ui.stepParts.appendChild(tr);
      }
      var row = allRows[i], have = done[key] || 0;
      row.cells[2].textContent = have + " / " + allCounts[key];
      row.className = now[key] ? "now" : have === allCounts[key] ? "done" : "";
    });
    arrange(s, state.explode === 0);
    body.setAttribute("data-step", String(s));
    body.setAttribute("data-placed", String(placed));
    requestRender();
  }

  function stepFromHash() {
    var m = /(?:^#|&)step=(-?\d+)/.exec(window.location.hash || "");
    return m ? parseInt(m[1], 10) : null;
  }
  function writeHash() {
    window.history.replaceState(null, "", "#step=" + state.step + (ui.explode.checked ? "&exploded=1" : ""));
  }
  function setStep(s, updateHash) {
    s = Math.max(1, Math.min(steps || 1, Math.round(s) || 1));
    if (s === state.step && body.hasAttribute("data-step")) return;
    state.step = s;
    showStep();
    if (updateHash) {
      try {
        writeHash();
      } catch (err) {
        // Some browsers refuse history changes on local files; the step still shows.
      }
    }
  }

  // ---------------------------------------------------------------- view controls

  function setExplode(on) {
    var from = state.explode, to = on ? 1 : 0;
    var fromCam = { target: camera.target.slice(), dist: camera.dist }, goal = fitted(layouts[to]);
    ui.explode.checked = on;
    body.setAttribute("data-exploded", on ? "1" : "0");
    try { writeHash(); } catch (err) { /* as in setStep */ }
    // Whole pieces while anything is apart; bare again once assembled.
    arrange(state.step, false);
    animate(450, function (t) {
      state.explode = lerp(from, to, t);
      if (t >= 1 && to === 0) arrange(state.step, true);
      camera.target = [0, 1, 2].map(function (k) { return lerp(fromCam.target[k], goal.target[k], t); });
      camera.dist = lerp(fromCam.dist, goal.dist, t);
    });
  }
  function resetView() {
    moved = false;
    var goal = fitted(layouts[ui.explode.checked ? 1 : 0]);
    camera.target = goal.target;
    camera.dist = goal.dist;
    camera.az = 45 * Math.PI / 180;
    camera.el = 30 * Math.PI / 180;
    requestRender();
  }
  // Until the camera is moved by hand, a resized view refits the model.
  var moved = false;
  function refit() {
    if (moved || animation) return requestRender();
    var goal = fitted(layouts[ui.explode.checked ? 1 : 0]);
    camera.target = goal.target;
    camera.dist = goal.dist;
    requestRender();
  }
  function orbit(dx, dy) {
    moved = true;
    camera.az -= dx * 0.008;
    camera.el = Math.max(-1.55, Math.min(1.55, camera.el + dy * 0.008));
  }
  function pan(dx, dy) {
    moved = true;
    var view = lookAt(eye(), camera.target, UP, new Float32Array(16)), wpp = worldPerPixel();
    for (var k = 0; k < 3; k++) {
      camera.target[k] += (-dx * view[4 * k] + dy * view[4 * k + 1]) * wpp;
    }
  }
  function zoom(factor) {
    moved = true;
    var r = layouts[state.explode > 0.5 ? 1 : 0].radius;
    camera.dist = Math.max(r * 0.05, Math.min(r * 20, camera.dist * factor));
  }

  var pointers = {}, gesture = null;
  function pointerList() { return Object.keys(pointers).map(function (k) { return pointers[k]; }); }
  function twoFinger() {
    var p = pointerList();
    return {
      x: (p[0].x + p[1].x) / 2, y: (p[0].y + p[1].y) / 2,
      d: Math.hypot(p[0].x - p[1].x, p[0].y - p[1].y) || 1
    };
  }
  canvas.addEventListener("pointerdown", function (e) {
    canvas.focus();
    try { canvas.setPointerCapture(e.pointerId); } catch (err) { /* a synthetic pointer */ }
    pointers[e.pointerId] = { x: e.clientX, y: e.clientY };
    var n = pointerList().length;
    gesture = n >= 2 ? { kind: "pinch", last: twoFinger() }
      : { kind: e.button === 2 || e.button === 1 || e.shiftKey || e.ctrlKey || e.metaKey ? "pan" : "orbit" };
    e.preventDefault();
  });
  canvas.addEventListener("pointermove", function (e) {
    var p = pointers[e.pointerId];
    if (!p || !gesture) return;
    var dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    if (gesture.kind === "pinch") {
      if (pointerList().length < 2) return;
      var now = twoFinger();
      zoom(gesture.last.d / now.d);
      pan(now.x - gesture.last.x, now.y - gesture.last.y);
      gesture.last = now;
    } else if (gesture.kind === "pan") {
      pan(dx, dy);
    } else {
      orbit(dx, dy);
    }
    requestRender();
  });
  function pointerEnd(e) {
    delete pointers[e.pointerId];
    var n = pointerList().length;
    gesture = n >= 2 ? { kind: "pinch", last: twoFinger() } : n === 1 ? { kind: "orbit" } : null;
  }
  canvas.addEventListener("pointerup", pointerEnd);
  canvas.addEventListener("pointercancel", pointerEnd);
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  canvas.addEventListener("dblclick", resetView);
  canvas.addEventListener("wheel", function (e) {
    var lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
    zoom(Math.exp(Math.max(-200, Math.min(200, e.deltaY * lines)) * 0.0015));
    requestRender();
    e.preventDefault();
  }, { passive: false });

  ui.first.addEventListener("click", function () { setStep(1, true); });
  ui.prev.addEventListener("click", function () { setStep(state.step - 1, true); });
  ui.next.addEventListener("click", function () { setStep(state.step + 1, true); });
  ui.last.addEventListener("click", function () { setStep(steps, true); });
  ui.slider.addEventListener("input", function () { setStep(parseInt(ui.slider.value, 10), true); });
  ui.explode.addEventListener("change", function () { setExplode(ui.explode.checked); });
  ui.reset.addEventListener("click", resetView);
  window.addEventListener("hashchange", function () {
    var s = stepFromHash();
    if (s !== null) setStep(s, false);
  });
  window.addEventListener("keydown", function (e) {
    if (e.altKey || e.ctrlKey || e.metaKey || e.defaultPrevented) return;
    var t = e.target;
    // The slider moves itself with the arrow keys; text fields keep their keys.
    if (t && t.tagName === "INPUT" && t.type === "range") return;
    var key = e.key, handled = true;
    if (key === "ArrowRight" || key === "PageDown") setStep(state.step + 1, true);
    else if (key === "ArrowLeft" || key === "PageUp") setStep(state.step - 1, true);
    else if (key === "Home") setStep(1, true);
    else if (key === "End") setStep(steps, true);
    else if (key === "e" || key === "E") setExplode(!ui.explode.checked);
    else if (key === "r" || key === "R") resetView();
    else handled = false;
    if (handled) e.preventDefault();
  });
  canvas.addEventListener("webglcontextlost", function (e) { e.preventDefault(); });
  canvas.addEventListener("webglcontextrestored", function () {
    if (initGL()) requestRender();
  });
  if (window.ResizeObserver) new ResizeObserver(refit).observe(canvas);
  else window.addEventListener("resize", refit);

  // ---------------------------------------------------------------- start

  ui.slider.max = String(Math.max(1, steps));
  ui.slider.disabled = steps <= 1;
  ui.summary.textContent = model.pieces.length + (model.pieces.length === 1 ? " piece" : " pieces") +
    " in " + steps + (steps === 1 ? " step" : " steps") + ", " + model.parts.length +
    (model.parts.length === 1 ? " part type" : " part types") + ", " + model.colors.length +
    (model.colors.length === 1 ? " colour" : " colours");
  ui.footer.textContent = "Made by " + model.generator + ". Drawn with WebGL in this page; it needs no network.";

  // Without WebGL the lists and the step controls still work.
  var drawing = initGL();
  if (/(?:^#|&)exploded=1/.test(window.location.hash || "")) {
    ui.explode.checked = true;
    state.explode = 1;
  }
  body.setAttribute("data-exploded", ui.explode.checked ? "1" : "0");
  resetView();
  var start = stepFromHash();
  setStep(start === null ? 1 : start, false);
  if (!drawing) return;

  // "#bench=N": draw N frames at once, turning the model, and report the
  // frame rate, the triangles a frame draws and the script's own time a
  // frame (in the console and as the body's data-fps, data-triangles and
  // data-script-ms).
  var bench = /(?:^#|&)bench=(\d+)/.exec(window.location.hash || "");
  if (bench) {
    var frames = Math.max(1, parseInt(bench[1], 10)), pixel = new Uint8Array(4), script = 0;
    render();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    var t0 = performance.now();
    for (var i = 0; i < frames; i++) {
      var t1 = performance.now();
      orbit(6, 0);
      render();
      script += performance.now() - t1;
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    }
    var fps = frames * 1000 / Math.max(1, performance.now() - t0);
    body.setAttribute("data-fps", fps.toFixed(1));
    body.setAttribute("data-triangles", String(state.triangles));
    body.setAttribute("data-script-ms", (script / frames).toFixed(2));
    console.log("brickwright viewer: " + model.pieces.length + " pieces, step " + state.step + ", " +
      frames + " frames, " + fps.toFixed(1) + " frames a second at " + canvas.width + "x" +
      canvas.height + ", " + state.triangles + " triangles a frame, script " +
      (script / frames).toFixed(2) + " ms a frame");
  }
})();
