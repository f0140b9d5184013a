//! What the commands print: the build's summary, and the stability
//! findings of `build` and `verify`.

use std::path::Path;

use anyhow::{Context, Result};

use brickwright::pipeline::{BuildReport, StabilityReport};

use super::args::GroundArg;

/// The summary of a finished build written to `out_dir`: size, parts,
/// files, repairs, quality, stability and time.
pub fn build_summary(r: &BuildReport, out_dir: &Path) {
    let opts_out = out_dir;
    outln!(
            "{} -> {}: {} pieces in {} steps, {} voxels ({:.1} voxels a piece), {}x{} studs x {} bricks high, verified",
            r.input, opts_out.display(), r.pieces, r.steps, r.voxels, r.voxels_per_piece, r.grid[0], r.grid[1],
            fmt_bricks(r.grid[2], r.layer_ldu)
        );
    outln!(
        "  {:>5}   {:<6} {:<30} {:<22} BrickLink",
        "count",
        "part",
        "name",
        "colour"
    );
    for p in &r.parts {
        let bl_color = p.bricklink_color.map_or_else(
            || "no BrickLink colour".to_string(),
            |c| format!("colour {c}"),
        );
        outln!(
            "  {:>5} x {:<6} {:<30} {:<22} {} {}",
            p.count,
            p.part,
            p.name,
            p.color_name,
            p.bricklink,
            bl_color
        );
    }
    let is_step = |f: &str| {
        std::path::Path::new(f)
            .parent()
            .is_some_and(|d| d.ends_with("steps"))
    };
    let steps: Vec<&String> = r.outputs.iter().filter(|f| is_step(f)).collect();
    for f in r.outputs.iter().filter(|f| !is_step(f)) {
        match r.booklet_pages.filter(|_| f.ends_with(".pdf")) {
            Some(n) => outln!("  wrote {f} ({n} pages)"),
            None => outln!("  wrote {f}"),
        }
    }
    if let Some(first) = steps.first() {
        let dir = std::path::Path::new(first.as_str())
            .parent()
            .unwrap_or(std::path::Path::new("."));
        outln!("  wrote {} step images in {}", steps.len(), dir.display());
    }
    let rep = &r.repairs;
    if rep.joined_islands + rep.thickened_voxels + rep.evened_voxels + rep.extra_cells > 0 {
        outln!(
                "  repairs: {} islands joined ({} voxels of supports and bridges), {} voxels added to make one-layer sheets two layers thick, {} voxels added to even flat tops to whole courses, {} cells outside the surface filled to join thin features",
                rep.joined_islands, rep.support_voxels, rep.thickened_voxels, rep.evened_voxels, rep.extra_cells
            );
    }
    if let Some(h) = &r.hollow {
        outln!(
            "  hollow: walls {} thick, {} pieces ({} inside as pillars) and {:.0} g where the solid build takes {} pieces and {:.0} g ({:.0}% of its pieces, {:.0}% of its mass)",
            h.wall, h.hollow.pieces, h.inner_pieces, h.hollow.mass_g, h.solid.pieces, h.solid.mass_g,
            100.0 * h.pieces_share, 100.0 * h.mass_share
        );
    }
    let q = &r.quality;
    outln!(
            "  quality: {} voxels left out, {:.0}% of seams continued, {:.1} voxels a piece, {:.0}% 1x1s, {} studs across (asked {})",
            q.left_out,
            100.0 * q.seams_continued,
            q.voxels_per_piece,
            100.0 * q.share_1x1,
            q.extent_studs,
            q.requested_studs.map_or("by height".to_string(), |n| n.to_string())
        );
    if r.options.slopes && q.stair_edges.top + q.stair_edges.underside > 0 {
        outln!(
            "  stair edges: {} of {} on top capped with slopes, {} of {} underneath with inverted slopes",
            q.stair_edges_capped.top,
            q.stair_edges.top,
            q.stair_edges_capped.underside,
            q.stair_edges.underside
        );
    }
    outln!(
            "  seams: {} of {} vertical seams continue into the course above ({:.0}%; lower is stronger)",
            r.seams.continued,
            r.seams.seams,
            100.0 * r.seams.fraction
        );
    if let Some(st) = &r.stability {
        print_build_stability(st);
    }
    let s = &r.seconds;
    outln!(
            "  search: {} nodes, {} candidates, {} joins; time: load {:.2}s, voxelize {:.2}s, search {:.2}s, verify {:.2}s, stability {:.2}s, render {:.2}s, booklet {:.2}s, write {:.2}s",
            r.search.nodes, r.search.candidates, r.search.joins, s.load, s.voxelize, s.search, s.verify, s.stability, s.render, s.booklet, s.write
        );
}

/// The stability lines of the build summary.
fn print_build_stability(st: &StabilityReport) {
    // Cut short before the finished model was analysed: the scores are
    // the steps checked.
    let unknown = st.stress_map == brickwright::physics::StressMap::Checked;
    let verdict = match (st.first_failure, st.complete, unknown) {
        (None, true, _) => "stands at every step".to_string(),
        (None, false, false) => format!(
            "checked {} steps before its time budget ran out; they and the finished model stand",
            st.steps_checked
        ),
        (None, false, true) => format!(
            "checked {} steps before its time budget ran out; they stand, and the finished model was not analysed in time",
            st.steps_checked
        ),
        (Some(step), _, _) => format!("does not stand from step {step} on"),
    };
    // Too big for the finished model's program in the budget: its scores
    // are those of an equilibrium that certified it, one of many, which
    // may use a joint to its capacity where the least-usage one does not.
    let whose = match st.stress_map {
        brickwright::physics::StressMap::Checked => "steps checked",
        brickwright::physics::StressMap::Certificates => {
            "finished model (an equilibrium found, not the least-usage one)"
        }
        brickwright::physics::StressMap::Program => "finished model",
    };
    outln!(
        "  stability: {verdict}; {whose}: lowest score {:.2}, mean {:.2} (score = 1 - share of stud clutch used; {} {})",
        st.min_score,
        st.mean_score,
        st.solves,
        if st.solves == 1 { "analysis" } else { "analyses" }
    );
    for line in &st.repairs {
        outln!("  repaired {line}");
    }
    match st.stands_on_baseplate {
        Some(true) => outln!(
            "  hint: it stands at every step when built on a baseplate, whose studs hold the bottom course"
        ),
        Some(false) => outln!("  (it would not stand on a baseplate either)"),
        None => {}
    }
}

/// A height of `layers` layers `layer_ldu` high, in bricks (24 LDU).
fn fmt_bricks(layers: i32, layer_ldu: i32) -> String {
    let ldu = layers * layer_ldu;
    if ldu % 24 == 0 {
        (ldu / 24).to_string()
    } else {
        format!("{:.2}", f64::from(ldu) / 24.0)
    }
}

/// Prints the static force analysis of every step; whether it all stands.
pub fn stability(
    file: &Path,
    model: &brickwright::ldraw::LdrModel,
    asm: &brickwright::assembly::Assembly,
    ground: GroundArg,
) -> Result<bool> {
    use brickwright::physics::{analyze_steps, Ground, Params};
    let (ground, on) = match ground {
        GroundArg::Table => (Ground::Table, "on a table"),
        GroundArg::Baseplate => (Ground::Baseplate, "on a baseplate"),
    };
    let params = Params::default().with_ground(ground);
    let s = analyze_steps(asm, &params, false)
        .with_context(|| format!("{}: stability analysis", file.display()))?;
    let a = &s.last;
    let stands = s.first_failure.is_none();
    outln!(
        "{}: stability: {}: min score {:.3}, mean {:.3}, max clutch usage {:.3} (clutch {} N a stud, {on})",
        file.display(),
        if stands { "stands at every step" } else { "FAILS" },
        a.min_score,
        a.mean_score,
        a.max_usage,
        params.clutch_n
    );
    let describe = |i: usize| {
        let p = &asm.pieces[i];
        let st = &a.pieces[i];
        let what = if st.falls {
            "falls".to_string()
        } else if st.breaks {
            format!("breaks off, clutch usage {:.3}", st.usage)
        } else {
            format!("clutch usage {:.3}, score {:.3}", st.usage, st.score)
        };
        let line = model
            .parts
            .get(i)
            .map_or_else(String::new, |r| format!("line {}, ", r.line));
        format!(
            "piece #{i} ({line}{}, step {}): {what}",
            p.placement.part.spec().id,
            p.step.0
        )
    };
    if !a.pieces.is_empty() {
        outln!("  weakest pieces of the finished build:");
        for i in a.weakest(5) {
            outln!("    {}", describe(i));
        }
    }
    if let Some(step) = s.first_failure {
        let check = s.steps.iter().find(|c| c.step == step);
        outln!("  first failing step: {step}");
        if let Some(c) = check {
            for &i in c.weakest.iter().take(3) {
                let p = &asm.pieces[i];
                outln!(
                    "    piece #{i} ({}{}, step {})",
                    model
                        .parts
                        .get(i)
                        .map_or_else(String::new, |r| format!("line {}, ", r.line)),
                    p.placement.part.spec().id,
                    p.step.0
                );
            }
        }
    }
    outln!(
        "  {} steps checked: {} programs solved, {} groups carried over, {:.2} s",
        s.steps.len(),
        s.solves,
        s.reused,
        s.seconds
    );
    Ok(stands)
}
