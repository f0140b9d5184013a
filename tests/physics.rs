//! Known answers of the static force analysis: structures whose verdict
//! (and, where it is simple, whose clutch usage) can be worked out by hand,
//! and the staircase examples StableLego publishes.
//!
//! Units in the hand computations: lengths in studs, weights in newtons
//! (catalog mass x 9.81 m/s²), the default clutch T = 1.8 N a stud.

use brickwright::assembly::{Assembly, Placed, Placement, Step, StepGrouping};
use brickwright::catalog::{Color, PartKind};
use brickwright::geom::{Cell, Rot};
use brickwright::physics::{
    analyze, analyze_steps, analyze_steps_from, analyze_steps_told, analyze_steps_with_finished,
    analyze_steps_within, Ground, Params, StressMap, CLUTCH_N, GRACE, GRAVITY,
};

use Rot::{R0, R90};

/// One piece: part, x, y, z (layer), turn, step.
type P = (&'static str, i32, i32, i32, Rot, u32);

/// An assembly on brick layers from pieces in build order.
fn build(pieces: &[P]) -> Assembly {
    Assembly {
        pieces: pieces
            .iter()
            .map(|&(id, x, y, z, rot, step)| Placed {
                placement: Placement::new(
                    PartKind::from_id(id).expect("catalog part"),
                    Cell::new(x, y, z),
                    rot,
                ),
                step: Step(step),
                color: Color::RED,
            })
            .collect(),
        layer_ldu: 24,
    }
}

/// The weight of a part in newtons.
fn weight(id: &str) -> f64 {
    f64::from(PartKind::from_id(id).unwrap().spec().mass_g) / 1000.0 * GRAVITY
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

#[test]
fn a_brick_on_the_ground_stands_using_no_clutch() {
    let a = analyze(&build(&[("3001", 0, 0, 0, R0, 1)]), &Params::default()).unwrap();
    assert!(a.stands());
    assert_eq!(a.pieces[0].usage, 0.0);
    assert_eq!((a.min_score, a.mean_score, a.max_usage), (1.0, 1.0, 0.0));
}

#[test]
fn a_balanced_t_on_a_column_stands_on_compression_alone() {
    // A 2x2 column two bricks high; a 2x4 centred across its top.
    let asm = build(&[
        ("3003", 1, 0, 0, R0, 1),
        ("3003", 1, 0, 1, R0, 2),
        ("3001", 0, 0, 2, R0, 3),
    ]);
    let a = analyze(&asm, &Params::default()).unwrap();
    assert!(a.stands(), "{a:?}");
    for p in &a.pieces {
        assert!(p.usage < 1e-4, "{a:?}");
    }
}

/// A cantilever on a baseplate: a 2x4 base on the plate at x 0..4; a 2xL
/// arm one brick up from x 3 (one column of 2 studs on the base, reaching
/// L - 1 studs out); on the arm's far end, `h` 2x4 bricks turned across
/// (2 studs along x) stacked as a load.
fn cantilever(arm: &'static str, len: i32, h: i32) -> Assembly {
    let mut p: Vec<P> = vec![("3001", 0, 0, 0, R0, 1), (arm, 3, 0, 1, R0, 2)];
    for k in 0..h {
        p.push(("3001", len + 1, -1, 2 + k, R90, 3 + k as u32));
    }
    build(&p)
}

/// The usage of the arm's joint, by hand. The arm turns about the base's
/// edge x = 4 (compression there); its two studs at x = 3.5 pull with t
/// each, lever 0.5: 2 * 0.5 * t = M, so usage = t / T = M / T. The arm's
/// centre is at 3 + L/2 (lever L/2 - 1); the load's at L + 2 (lever L - 2).
fn cantilever_usage(arm: &str, len: i32, h: i32) -> f64 {
    let l = f64::from(len);
    let m = weight(arm) * (l / 2.0 - 1.0) + f64::from(h) * weight("3001") * (l - 2.0);
    m / CLUTCH_N
}

#[test]
fn a_cantilever_holds_at_a_short_reach_and_breaks_at_a_long_one() {
    let params = Params::default().with_ground(Ground::Baseplate);
    // Reach 6 studs to the load (a 2x6 arm): (0.0326 * 2 + 15 * 0.0228 * 4) / 1.8 = 0.79.
    let short = analyze(&cantilever("2456", 6, 15), &params).unwrap();
    let want = cantilever_usage("2456", 6, 15);
    assert!((0.78..0.80).contains(&want), "{want}");
    assert!(short.stands(), "{short:?}");
    assert!(
        close(short.pieces[1].usage, want, 0.01),
        "{} vs {want}",
        short.pieces[1].usage
    );
    // Reach 8 (a 2x8 arm): (0.0430 * 3 + 15 * 0.0228 * 6) / 1.8 = 1.21: it breaks off.
    let long = analyze(&cantilever("3007", 8, 15), &params).unwrap();
    let want = cantilever_usage("3007", 8, 15);
    assert!((1.20..1.22).contains(&want), "{want}");
    assert!(!long.stands());
    let arm = long.pieces[1];
    assert!(arm.breaks && !arm.falls, "{arm:?}");
    assert!(close(arm.usage, want, 0.01), "{} vs {want}", arm.usage);
    let mut weakest = long.weakest(2);
    weakest.sort_unstable();
    assert_eq!(weakest, [0, 1]);
    // The base breaks with it (the same joint); the load is fine.
    assert!(long.pieces[0].breaks);
    assert!(long.pieces[2].usage < 1e-4);
}

/// The long cantilever above (its arm's joint at 1.21 of its clutch), with
/// its load also hung from a 2x6 beam on a post beside it by a chain of
/// four 1x1 bricks. The force program's least usage leaves the whole load
/// on the arm, overloaded (the chain's joints and the post's cost more in
/// its sum than the arm's one joint saves), though the chain can take the
/// excess: another equilibrium holds every joint within its capacity, so
/// the model stands (the safe theorem), its stress the least usage within
/// capacity, the arm's joint at it.
#[test]
fn a_model_another_equilibrium_holds_within_capacity_stands() {
    let params = Params::default().with_ground(Ground::Baseplate);
    let (h, chain) = (15, 4);
    let mut p: Vec<P> = vec![("3001", 0, 0, 0, R0, 1), ("3007", 3, 0, 1, R0, 2)];
    for k in 0..h {
        p.push(("3001", 9, -1, 2 + k, R90, 3));
    }
    for k in 0..chain {
        p.push(("3005", 9, 0, 2 + h + k, R0, 4));
    }
    for z in 0..2 + h + chain {
        p.push(("3003", 13, 0, z, R0, 5));
    }
    p.push(("2456", 9, 0, 2 + h + chain, R0, 6));
    let a = analyze(&build(&p), &params).unwrap();
    assert!(a.stands(), "{a:?}");
    assert!(a.max_usage <= 1.0, "{}", a.max_usage);
    // The arm takes all it can; the chain the rest.
    assert!(close(a.pieces[1].usage, 1.0, 1e-3), "{}", a.pieces[1].usage);
    // Without the chain and the post it breaks off, as above.
    let alone = analyze(&cantilever("3007", 8, 15), &params).unwrap();
    assert!(!alone.stands() && alone.pieces[1].breaks);
}

/// Two 1x2 columns two bricks high at x 0..2 and 16..18 on a table, a 1x8
/// arm on each reaching for the middle (one stud on its column), and a
/// 1x4 keystone across the arms' ends; `steps` are the seven pieces'
/// steps. Each half's centre of mass, (2 * 0.80 * 1 + 2.92 * 5) / 4.52 =
/// 3.58, lies past its column's edge at x = 2, so an arm alone tips its
/// column over; the keystone joins the halves into a symmetric bridge
/// whose centre is between the columns.
fn bridge(steps: [u32; 7]) -> Assembly {
    let at = [(0, 0), (0, 1), (16, 0), (16, 1), (1, 2), (9, 2), (7, 3)];
    let parts = ["3004", "3004", "3004", "3004", "3008", "3008", "3010"];
    let pieces: Vec<P> = (0..7)
        .map(|i| (parts[i], at[i].0, 0, at[i].1, R0, steps[i]))
        .collect();
    build(&pieces)
}

#[test]
fn a_bridge_stands_only_once_its_keystone_is_in() {
    let asm = bridge([1, 1, 2, 2, 3, 4, 5]);
    let params = Params::default();
    let steps = analyze_steps(&asm, &params, false).unwrap();
    let stands: Vec<bool> = steps.steps.iter().map(|s| s.stands).collect();
    assert_eq!(stands, [true, true, false, false, true], "{steps:?}");
    assert_eq!(steps.first_failure, Some(3));
    assert!(steps.last.stands());
    // The columns' groups are separate until the keystone: steps 3 and 4
    // each re-solve only the half that grew.
    assert!(steps.reused >= 2, "{steps:?}");
    // The same answer when stopping early, and from scratch at the end.
    let early = analyze_steps(&asm, &params, true).unwrap();
    assert_eq!(early.first_failure, Some(3));
    assert_eq!(early.steps.len(), 3);
    let whole = analyze(&asm, &params).unwrap();
    assert!(whole.stands());
    assert_eq!(whole.pieces, steps.last.pieces);
}

#[test]
fn checking_from_a_later_step_agrees_with_checking_every_step() {
    // The bridge again, one piece a step: steps before `from` are taken as
    // standing; the rest must read exactly as a check from step 1 does.
    let asm = bridge([1, 2, 3, 4, 5, 6, 7]);
    let params = Params::default();
    let all = analyze_steps(&asm, &params, false).unwrap();
    assert_eq!(all.first_failure, Some(5));
    for from in 1..=7 {
        let part = analyze_steps_from(&asm, &params, false, None, from).unwrap();
        let tail: Vec<_> = all.steps.iter().filter(|s| s.step >= from).collect();
        assert_eq!(part.steps.len(), tail.len(), "from {from}");
        for (a, b) in part.steps.iter().zip(tail) {
            assert_eq!(a.step, b.step);
            assert_eq!(a.stands, b.stands, "step {} from {from}", a.step);
            assert!(
                (a.min_score - b.min_score).abs() < 1e-6,
                "step {} from {from}",
                a.step
            );
        }
        assert_eq!(
            part.first_failure,
            if from <= 6 { Some(from.max(5)) } else { None }
        );
        assert_eq!(part.last.pieces, all.last.pieces);
    }
    // Past the last step: the last step is checked, whole.
    let past = analyze_steps_from(&asm, &params, false, None, 9).unwrap();
    assert_eq!(past.steps.len(), 1);
    assert_eq!(past.steps[0].step, 7);
    assert!(past.steps[0].stands);
    // Given the finished model's analysis, the last step checked whole
    // takes it: nothing is solved.
    let whole = analyze(&asm, &params).unwrap();
    let given =
        analyze_steps_with_finished(&asm, &params, false, None, 9, None, Some(&whole)).unwrap();
    assert_eq!(given.steps, past.steps);
    assert_eq!(given.last.pieces, whole.pieces);
    assert_eq!(given.solves, 0);
}

/// A 1x4 base on a table, a 1x6 overhang clutched to its last stud
/// (x 3..9, centre 6), a 1x2 counterweight on the base's other end
/// (x 0..2, centre 1). Base and overhang alone: centre of mass
/// (1.52 * 2 + 2.24 * 6) / 3.76 = 4.38, past the base's edge x = 4: it
/// tips. With the counterweight: (3.04 + 13.44 + 0.80) / 4.56 = 3.79: it
/// stands.
fn overhang(counterweight_first: bool) -> Assembly {
    let (o, c) = if counterweight_first { (3, 2) } else { (2, 3) };
    let mut p = vec![
        ("3010", 0, 0, 0, R0, 1),
        ("3009", 3, 0, 1, R0, o),
        ("3004", 0, 0, 1, R0, c),
    ];
    p.sort_by_key(|q| q.5);
    build(&p)
}

#[test]
fn an_overhang_falls_when_built_before_its_counterweight() {
    let params = Params::default();
    let wrong = analyze_steps(&overhang(false), &params, false).unwrap();
    let stands: Vec<bool> = wrong.steps.iter().map(|s| s.stands).collect();
    assert_eq!(stands, [true, false, true]);
    assert_eq!(wrong.first_failure, Some(2));
    assert!(wrong.last.stands());
    let right = analyze_steps(&overhang(true), &params, false).unwrap();
    assert!(right.steps.iter().all(|s| s.stands), "{right:?}");
    assert_eq!(right.first_failure, None);
    // Only the last step needs a program (the base and the counterweight
    // rest straight on what is below them), and the finished build is that
    // very program: it is solved once, and reads as a solve afresh does.
    assert_eq!(right.solves, 1, "{right:?}");
    // Its time is that program's, carried over with its answer.
    assert!(right.last.solve_seconds > 0.0, "{right:?}");
    assert!(right.last.solve_seconds <= right.seconds, "{right:?}");
    assert_eq!(
        right.last.pieces,
        analyze(&overhang(true), &params).unwrap().pieces
    );
    // The overhang's clutch: moment 2.24 g * 9.81 * (6 - 4) about the base
    // edge on one stud at lever 0.5.
    let want = weight("3009") * 2.0 / 0.5 / CLUTCH_N;
    let got = right.last.pieces[2].usage;
    assert!(close(got, want, 0.01), "{got} vs {want}");
}

/// The overhang of [`overhang`] built first, two 1x2s stacked on its far
/// end (x 7..9), then a counterweight of 1x2s stacked on the base's other
/// end (x 0..2), one a step. About the base's edge (x 4) the overhang and
/// its load turn 2.24 g * 2 + 2 * 0.80 g * 4 = 10.88 g studs, the base
/// 1.52 g * 2 = 3.04 the other way and each counterweight 0.80 g * 3 =
/// 2.4: it tips until the fourth (12.64).
#[test]
fn a_failure_is_carried_by_its_proof_until_a_counterweight_holds_it() {
    let mut pieces = vec![
        ("3010", 0, 0, 0, R0, 1),
        ("3009", 3, 0, 1, R0, 2),
        ("3004", 7, 0, 2, R0, 3),
        ("3004", 7, 0, 3, R0, 4),
    ];
    for k in 0..4 {
        pieces.push(("3004", 0, 0, 1 + k, R0, 5 + k as u32));
    }
    let asm = build(&pieces);
    let params = Params::default();
    let steps = analyze_steps(&asm, &params, false).unwrap();
    let stands: Vec<bool> = steps.steps.iter().map(|s| s.stands).collect();
    assert_eq!(
        stands,
        [true, false, false, false, false, false, false, true],
        "{steps:?}"
    );
    for check in &steps.steps {
        let whole = analyze(&asm.through_step(check.step), &params).unwrap();
        assert_eq!(check.stands, whole.stands(), "step {}", check.step);
    }
    // Steps 3 to 7 fail by the proof of step 2 (the base and its overhang
    // tip over the base's edge; each new piece moves with the one it
    // rests on), with no program; the step the counterweight holds ends
    // it.
    assert_eq!(steps.failures_carried, 5, "{steps:?}");
    // Its failing pieces are named at every step it fails.
    for check in &steps.steps[1..7] {
        assert!(check.min_score == 0.0 && !check.weakest.is_empty());
    }
}

/// The finished model analysed alongside the steps (as the repairs ask
/// for it): the same steps and `last` as a check without it, nothing
/// solved twice, and `finished` is what `analyze` gives, even when the
/// check stops at a failure before the end.
#[test]
fn the_finished_model_is_analysed_alongside_the_steps() {
    let params = Params::default();
    for (name, asm) in [
        ("stands", overhang(true)),
        ("fails at step 2", overhang(false)),
        ("mug", fixture_build("mug.obj", 16)),
    ] {
        let whole = analyze(&asm, &params).unwrap();
        for stop in [true, false] {
            let plain = analyze_steps(&asm, &params, stop).unwrap();
            let both =
                analyze_steps_with_finished(&asm, &params, stop, None, 1, None, None).unwrap();
            assert!(plain.finished.is_none(), "{name}");
            assert_eq!(both.steps, plain.steps, "{name}");
            assert_eq!(both.first_failure, plain.first_failure, "{name}");
            assert_eq!(both.last.pieces, plain.last.pieces, "{name}");
            let finished = both.finished.as_ref().expect("made alongside");
            assert_eq!(finished.pieces, whole.pieces, "{name}");
            assert!(finished.solve_seconds > 0.0, "{name}");
            // The last step takes the finished model's answers instead of
            // solving them again; only a check stopped before the end
            // solves the finished model on top.
            let stopped = stop && plain.first_failure.is_some_and(|f| f < asm.step_count());
            assert!(
                both.solves <= plain.solves + usize::from(stopped),
                "{name}: {} against {}",
                both.solves,
                plain.solves
            );
            // Given the finished model's analysis, the check reads the
            // same and solves one program fewer.
            let given =
                analyze_steps_with_finished(&asm, &params, stop, None, 1, None, Some(&whole))
                    .unwrap();
            assert_eq!(given.steps, both.steps, "{name}");
            assert_eq!(given.last.pieces, both.last.pieces, "{name}");
            assert_eq!(given.finished.as_ref(), Some(&whole), "{name}");
            assert_eq!(given.solves + 1, both.solves, "{name}");
        }
    }
    // An analysis of another assembly is refused.
    let other = analyze(&overhang(true), &params).unwrap();
    let small = build(&[("3001", 0, 0, 0, R0, 1)]);
    assert!(
        analyze_steps_with_finished(&small, &params, true, None, 1, None, Some(&other)).is_err()
    );
    // Built before its counterweight, the overhang tips at step 2: the
    // check stops there, and the finished model (which stands) is still
    // analysed.
    let wrong =
        analyze_steps_with_finished(&overhang(false), &params, true, None, 1, None, None).unwrap();
    assert_eq!(wrong.first_failure, Some(2));
    assert!(!wrong.last.stands());
    assert!(wrong.finished.unwrap().stands());
}

/// A check with a deadline starts the finished model's analysis alongside
/// the steps once it is due (the deadline less the time it takes) instead
/// of stopping for it: past the deadline at once, it is made, once, and
/// is both `last` and `finished`; part way, the steps checked read as in
/// a check without a deadline, and so does the finished model.
#[test]
fn a_check_cut_short_makes_the_finished_model_alongside_the_steps() {
    let params = Params::default();
    let asm = fixture_build("mug.obj", 16);
    let whole = analyze(&asm, &params).unwrap();
    // No deadline: the analysis is never due, the last step is checked.
    let all = analyze_steps_within(&asm, &params, false, None).unwrap();
    assert!(all.complete);
    assert!(all.finished.is_none());
    assert_eq!(all.last.pieces, whole.pieces);
    // Past the deadline from the start: no step, the finished model only.
    let none = analyze_steps_within(&asm, &params, false, Some(std::time::Instant::now())).unwrap();
    assert!(!none.complete);
    assert!(none.steps.is_empty());
    assert_eq!(none.solves, 1);
    assert_eq!(none.last.pieces, whole.pieces);
    // Made alongside when the pool has a worker for it besides the
    // steps' (else after them, as `last`).
    assert_eq!(none.finished.is_some(), rayon::current_num_threads() > 1);
    if let Some(finished) = &none.finished {
        assert_eq!(finished.pieces, whole.pieces);
        assert!(finished.solve_seconds > 0.0);
    }
    // Part way (where depends on the machine's speed): a prefix of the
    // steps, the same.
    for share in [0.25, 0.5] {
        let deadline =
            std::time::Instant::now() + std::time::Duration::from_secs_f64(all.seconds * share);
        let part = analyze_steps_within(&asm, &params, false, Some(deadline)).unwrap();
        assert_eq!(part.steps, all.steps[..part.steps.len()]);
        if !part.complete {
            assert_eq!(part.last.pieces, whole.pieces);
        }
        if let Some(f) = &part.finished {
            assert_eq!(f.pieces, whole.pieces);
        }
    }
}

/// A check cut short whose finished model is not made within the grace
/// after its deadline does not wait for it: its `last` is the steps
/// checked (none here: the deadline passed long before the check began),
/// and its map says so.
#[test]
fn a_check_cut_short_past_its_grace_does_not_wait_for_the_finished_model() {
    let params = Params::default();
    let asm = fixture_build("house.obj", 24);
    let long_ago = std::time::Instant::now() - 2 * GRACE;
    let c = analyze_steps_within(&asm, &params, false, Some(long_ago)).unwrap();
    assert!(!c.complete);
    assert!(c.steps.is_empty());
    assert!(c.last.pieces.is_empty(), "{}", c.last.pieces.len());
    assert_eq!(c.map, StressMap::Checked);
    assert!(c.finished.is_none());
}

#[test]
fn a_piece_floating_in_the_air_falls() {
    let asm = build(&[("3001", 0, 0, 0, R0, 1), ("3001", 10, 0, 3, R0, 2)]);
    let a = analyze(&asm, &Params::default()).unwrap();
    assert!(!a.stands());
    assert!(!a.pieces[0].falls && a.pieces[1].falls);
    assert_eq!(a.pieces[1].score, 0.0);
    assert_eq!(a.weakest(1), [1]);
}

#[test]
fn a_leaning_tower_tips_over_once_its_centre_passes_its_base() {
    // 1x4 bricks each two studs further right: the centre of k bricks is
    // at 2 + (k - 1), past the base's edge x = 4 from k = 4 on.
    let stair = |k: i32| -> Assembly {
        let p: Vec<P> = (0..k)
            .map(|i| ("3010", 2 * i, 0, i, R0, 1 + i as u32))
            .collect();
        build(&p)
    };
    let params = Params::default();
    assert!(analyze(&stair(2), &params).unwrap().stands());
    let four = analyze(&stair(4), &params).unwrap();
    assert!(four.pieces.iter().any(|p| p.falls), "{four:?}");
    let steps = analyze_steps(&stair(5), &params, false).unwrap();
    assert_eq!(steps.first_failure, Some(4));
}

/// StableLego's staircases (`stair_19`, `stair_20`, `stair_20_good` in its
/// `test_lego/`): 2x4 bricks, each two studs further along x and one
/// brick up, on a baseplate.
fn stair(n: i32, prop: bool) -> Assembly {
    let mut p: Vec<P> = (0..n)
        .map(|k| ("3001", 2 * k, 0, k, R0, 1 + k as u32))
        .collect();
    if prop {
        // A 1x2 across under the second brick's x = 4 column.
        p.push(("3004", 4, 0, 0, R90, n as u32 + 1));
    }
    build(&p)
}

/// The usage of the joint between stair bricks 0 and 1 with `n` bricks,
/// by hand: the N = n - 1 bricks above it have centres 2d - 2 studs past
/// the pivot x = 4 (d = 1..N), a moment of N (N - 1) W; its four studs
/// pull at levers 0.5 and 1.5 (two each): 4 T usage.
fn stair_usage(n: i32) -> f64 {
    let big = f64::from(n - 1);
    big * (big - 1.0) * weight("3001") / (4.0 * CLUTCH_N)
}

#[test]
fn stablelego_stairs_19_stands_20_breaks_and_a_prop_saves_20() {
    let params = Params::default().with_ground(Ground::Baseplate);
    let low = analyze(&stair(19, false), &params).unwrap();
    assert!(low.stands(), "StableLego: stair_19 is stable");
    assert!(
        close(low.max_usage, stair_usage(19), 0.01),
        "{}",
        low.max_usage
    );
    let high = analyze(&stair(20, false), &params).unwrap();
    assert!(!high.stands(), "StableLego: stair_20 collapses");
    assert!(
        close(high.max_usage, stair_usage(20), 0.01),
        "{}",
        high.max_usage
    );
    assert!(
        high.pieces.iter().all(|p| !p.falls),
        "it breaks, it does not tip"
    );
    let good = analyze(&stair(20, true), &params).unwrap();
    assert!(good.stands(), "StableLego: stair_20_good is stable");
    // On a table instead of a baseplate the stair tips over long before.
    let table = analyze(&stair(19, false), &Params::default()).unwrap();
    assert!(table.pieces.iter().any(|p| p.falls));
}

#[test]
fn the_analysis_is_deterministic_and_steps_agree_with_the_whole() {
    // A small running-bond block, four courses, grouped as `build` does.
    let mut p: Vec<P> = Vec::new();
    for z in 0..4 {
        for y in (0..4).step_by(2) {
            for x in (0..8).step_by(4) {
                let off = if z % 2 == 0 { 0 } else { 2 };
                p.push(("3001", x + off, y, z, R0, 1));
            }
        }
    }
    let mut asm = build(&p);
    asm.regroup(StepGrouping::Auto);
    let params = Params::default();
    let a = analyze(&asm, &params).unwrap();
    let b = analyze(&asm, &params).unwrap();
    assert_eq!(a.pieces, b.pieces);
    assert!(a.stands(), "{a:?}");
    let s = analyze_steps(&asm, &params, false).unwrap();
    assert_eq!(s.steps.len() as u32, asm.step_count());
    assert_eq!(s.last.pieces, a.pieces);
    // Every brick rests straight on the ones below: no step needs a solve,
    // only the finished block.
    assert_eq!(s.solves, 1, "{s:?}");
    assert!(s.steps.iter().all(|c| c.stands));
}

#[test]
fn bad_parameters_are_an_error_not_a_panic() {
    let asm = build(&[("3001", 0, 0, 0, R0, 1)]);
    assert!(analyze(&asm, &Params::default().with_clutch_n(0.0)).is_err());
    assert!(analyze(&asm, &Params::default().with_gravity(f64::NAN)).is_err());
    let empty = build(&[]);
    let a = analyze(&empty, &Params::default()).unwrap();
    assert!(a.stands() && a.pieces.is_empty());
    let s = analyze_steps(&empty, &Params::default(), true).unwrap();
    assert!(s.steps.is_empty() && s.first_failure.is_none());
}

/// The search's build of a fixture mesh, searched, sequenced and grouped
/// as `build` does it (bricks only).
fn fixture_build(name: &str, studs: u32) -> Assembly {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name);
    brickwright::pipeline::bricks_by_course(&path, studs).expect("the fixture builds")
}

/// The step check reuses and certifies what it can; on real builds every
/// step must get the verdict a full solve of that step's structure gives,
/// and the finished build the usage of every piece within 1e-6: the force
/// program's usages are unique, so the step check's answers for the
/// finished build (its own programs' or the whole model's) are the
/// whole analysis'. (A step's scores are those of the equilibrium that
/// certifies it, which need not be the program's.)
#[test]
fn every_step_of_a_real_build_agrees_with_a_full_solve() {
    let params = Params::default();
    for (name, studs) in [("mug.obj", 24), ("arch.obj", 24)] {
        let asm = fixture_build(name, studs);
        let fast = analyze_steps(&asm, &params, false).unwrap();
        assert!(fast.complete);
        assert_eq!(fast.steps.len() as u32, asm.step_count(), "{name}");
        for check in &fast.steps {
            let prefix = asm.through_step(check.step);
            let full = analyze(&prefix, &params).unwrap();
            assert_eq!(check.stands, full.stands(), "{name} step {}", check.step);
            assert!((0.0..=1.0).contains(&check.min_score), "{name}");
        }
        // Most steps are certified by a change near their new pieces.
        assert!(
            fast.certified + fast.reused > fast.solves,
            "{name}: {} certified, {} reused, {} solved",
            fast.certified,
            fast.reused,
            fast.solves
        );
        // Each certificate's region reaches the group's footing: none
        // needs the whole group's program on the mug (one on the mug and
        // two on the arch did when the region was the new pieces' ways down
        // and rings). One step of the arch takes one, of its 50 pieces: the
        // pieces placed by pushes alone at the steps before (see
        // `Certifier::spread_down`) carry their weight where its first
        // region, 23 pieces, finds no change, and the next ring holds
        // nine tenths of the group.
        let most = if name == "arch.obj" { 1 } else { 0 };
        assert!(
            fast.whole_certified <= most,
            "{name}: {}",
            fast.whole_certified
        );
        let whole = analyze(&asm, &params).unwrap();
        for (a, b) in fast.last.pieces.iter().zip(&whole.pieces) {
            assert!((a.usage - b.usage).abs() <= 1e-6, "{name}");
        }
    }
}

/// A mushroom: a 4 x 4 stem 10 units tall under a 20 x 20 cap 3 units
/// thick, as an OBJ of two boxes.
fn mushroom_obj() -> String {
    let mut obj = String::new();
    let boxes = [
        [-2.0, 0.0, -2.0, 2.0, 10.0, 2.0],
        [-10.0, 10.0, -10.0, 10.0, 13.0, 10.0],
    ];
    for (k, b) in boxes.iter().enumerate() {
        for x in [b[0], b[3]] {
            for y in [b[1], b[4]] {
                for z in [b[2], b[5]] {
                    obj.push_str(&format!("v {x} {y} {z}\n"));
                }
            }
        }
        let o = 8 * k + 1;
        for q in [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ] {
            let [a, b, c, d] = q.map(|i| i + o);
            obj.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
        }
    }
    obj
}

/// A real build that fails part way and goes on failing: the mushroom's
/// cap, course by course, hangs off its stem. Every step's verdict is the
/// whole structure's program's, and the steps after the first failure
/// are mostly carried by its proof, not solved.
#[test]
fn a_failing_real_build_carries_its_failure_and_agrees_with_a_full_solve() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mushroom.obj");
    std::fs::write(&path, mushroom_obj()).unwrap();
    let asm = brickwright::pipeline::bricks_by_course(&path, 24).expect("the mushroom builds");
    let params = Params::default();
    let fast = analyze_steps(&asm, &params, false).unwrap();
    assert!(fast.complete);
    let first = fast.first_failure.expect("its cap hangs off the stem");
    let after = fast
        .steps
        .iter()
        .filter(|c| c.step > first && !c.stands)
        .count();
    assert!(after >= 2, "{fast:?}");
    for check in &fast.steps {
        let full = analyze(&asm.through_step(check.step), &params).unwrap();
        assert_eq!(check.stands, full.stands(), "step {}", check.step);
    }
    // At 24 studs: fails from step 8 of 34, the 15 failing steps after
    // it all carried, 2 programs solved in all.
    assert!(4 * fast.failures_carried >= 3 * after, "{fast:?}");
}

/// The step check tells how far it is, a step at a time, as a progress
/// display needs: counts that only go up, against the build's steps, and
/// the same answer as without anyone told.
#[test]
fn the_step_check_tells_its_progress_in_steps() {
    let asm = fixture_build("mug.obj", 16);
    let params = Params::default();
    let told = std::cell::RefCell::new(Vec::new());
    let tell = |done, total| told.borrow_mut().push((done, total));
    let checked = analyze_steps_told(&asm, &params, false, None, 1, Some(&tell)).unwrap();
    let told = told.into_inner();
    let steps = u64::from(asm.step_count());
    assert_eq!(told.len() as u64, steps, "one report a step");
    assert!(told.iter().all(|&(_, total)| total == steps));
    assert!(told.windows(2).all(|w| w[0].0 < w[1].0));
    assert_eq!(told[0].0, 0);
    let quiet = analyze_steps(&asm, &params, false).unwrap();
    assert_eq!(checked.first_failure, quiet.first_failure);
    assert_eq!(checked.steps.len(), quiet.steps.len());
}
