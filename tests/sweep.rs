//! A slice of the sweep (`benches/sweep.sh`): fixtures at two sizes and
//! two seeds with every option set the sweep tries, each a whole run of
//! the binary that must exit 0 with the model whole and its build
//! verified. The full sweep (the shared meshes, 24-96 studs, seeds 1-3)
//! is a bench; this slice keeps an internal error from coming back
//! unnoticed in the tests.

use std::path::Path;
use std::process::Command;

/// The option sets of the sweep.
const OPTIONS: [&[&str]; 5] = [
    &[],
    &["--hollow"],
    &["--slopes"],
    &["--plates"],
    &["--palette", "layers"],
];

/// Meshes with overhangs, a cavity, a hole, several parts and colours.
const MESHES: [&str; 4] = ["mug.obj", "arch.obj", "floating.obj", "textured.glb"];

#[test]
fn fixtures_build_at_every_option_size_and_seed() {
    let bin = env!("CARGO_BIN_EXE_brickwright");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let tmp = tempfile::tempdir().unwrap();
    let mut failed = Vec::new();
    let mut runs = 0;
    for mesh in MESHES {
        for studs in ["24", "32"] {
            for seed in ["1", "2"] {
                for opts in OPTIONS {
                    runs += 1;
                    let out = tmp.path().join(format!("run{runs}"));
                    let run = Command::new(bin)
                        .arg("build")
                        .arg(fixtures.join(mesh))
                        .arg("-o")
                        .arg(&out)
                        .args(["--studs", studs, "--seed", seed])
                        .args(opts)
                        .args(["--stability", "off", "--formats", "ldr", "--quiet"])
                        .output()
                        .unwrap();
                    let what = format!("{mesh} --studs {studs} --seed {seed} {}", opts.join(" "));
                    if !run.status.success() {
                        failed.push(format!(
                            "{what}: {}: {}",
                            run.status,
                            String::from_utf8_lossy(&run.stderr).trim()
                        ));
                        continue;
                    }
                    let report: serde_json::Value = serde_json::from_str(
                        &std::fs::read_to_string(out.join("report.json")).unwrap(),
                    )
                    .unwrap();
                    let left = report["quality"]["left_out"].as_u64().unwrap();
                    let voxels = report["voxels_input"].as_u64().unwrap();
                    // Whole: nothing but a stray voxel no piece fits.
                    if left * 200 > voxels {
                        failed.push(format!("{what}: {left} of {voxels} voxels left out"));
                    }
                    let ldr = out.join(Path::new(mesh).with_extension("ldr"));
                    let check = Command::new(bin).arg("verify").arg(&ldr).output().unwrap();
                    if !check.status.success() {
                        failed.push(format!(
                            "{what}: verify: {}",
                            String::from_utf8_lossy(&check.stdout).trim()
                        ));
                    }
                    std::fs::remove_dir_all(&out).unwrap();
                }
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {runs} runs failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}
