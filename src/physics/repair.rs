//! Repairing a build order so that every intermediate structure stands.
//!
//! A finished model can stand while one of its intermediate structures
//! does not: an overhang put on before the piece that ties it back, a
//! bridge arm long before its keystone. [`reorder`] walks the build step
//! by step from the first step that fails and **defers** the pieces that
//! would break off or fall: they wait, in their original order, and are
//! offered again with every later step until the structure holds them.
//! A deferred piece takes with it every piece that can only connect
//! through it, so each step still joins what is built (the rewriting
//! system's guarantee). Each candidate step is checked as the step check
//! does (see [`physics`](super)): the equilibrium kept from the steps
//! before is changed to hold the new pieces, and the change found is
//! checked against every equation and bound; only where no change exists
//! does the full force analysis ([`analyze`](super::analyze)) say which pieces fail.
//! Nothing is accepted on a guess.
//!
//! The caller verifies the new order (connection and placeability). Where
//! every step the walk kept was certified so (from the first failure to
//! the end, nothing left waiting), those certificates are the check of the
//! new order's steps ([`Reordered::walked`]): a step is said to stand only
//! on an equilibrium checked against every equation and bound, as the
//! step check says it. Otherwise the caller checks every step again with
//! [`analyze_steps`](super::analyze_steps).

use std::collections::BTreeSet;

use serde::Serialize;

use super::certify::{Certifier, Verdict};
use super::model::{First, Structure};
use super::steps::check;
use super::{analyze_expecting, Analysis, Params, PhysicsError, PieceStress, StepCheck};
use crate::assembly::verify::Placing;
use crate::assembly::{Assembly, Placed, Step};

/// A piece the repair moved to a later step.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Moved {
    /// The piece's index in the original assembly.
    pub piece: usize,
    /// Its LDraw part.
    pub part: &'static str,
    /// Its step before the repair.
    pub from_step: u32,
    /// Its step after the repair.
    pub to_step: u32,
}

/// What [`reorder`] did.
#[derive(Debug, Clone)]
pub struct Reordered {
    /// The same pieces in the new order, steps renumbered.
    pub assembly: Assembly,
    /// The pieces that moved to a later step, in the original order.
    pub moved: Vec<Moved>,
    /// Force analyses run (a candidate step certified by a change to the
    /// kept equilibrium needs none).
    pub solves: usize,
    /// Candidate steps certified standing without one.
    pub certified: usize,
    /// The new order's steps from the first failure on, each certified
    /// standing by the walk; `None` where one was not (a step the full
    /// analysis held, or pieces still waiting at the end).
    pub walked: Option<Walked>,
}

/// The walk's check of the steps it certified (see [`Reordered::walked`]).
#[derive(Debug, Clone)]
pub struct Walked {
    /// A check for each step of the new order from the first failure on,
    /// as the step check gives it: every one stands.
    pub steps: Vec<StepCheck>,
    /// Each piece's stress (in the new order) in the equilibrium that
    /// certified its group at the last step: the finished model stands
    /// (its `solve_seconds` the walk's).
    pub last: Analysis,
}

/// Candidate steps a reorder may check, per step of the build, at most; a
/// build that needs more is left as it is.
const SOLVES_PER_STEP: usize = 4;

/// Pieces a repaired step may hold at most: deferring more into one step
/// would make a step no person can follow, so the reorder gives up.
pub const MAX_REPAIRED_STEP: usize = 3 * crate::assembly::STEP_PIECES;

/// Pieces that may wait at once, at most: the same as a repaired step
/// may hold. Pieces wait until a step holds them, and most come back
/// together with the step that ties them in; a walk with more waiting is
/// one where little or nothing of what follows stands (an overhang that
/// needs a support, not a later piece), and walking the rest of the build
/// with it costs an analysis each step (the bunny at 72 studs: nothing
/// from step 32 on stood, and 245 pieces waited by step 64, half a minute
/// in, before the walk ran out of time).
pub const MAX_WAITING: usize = MAX_REPAIRED_STEP;

/// Re-sequences `assembly`, whose steps before `first_failure` stand, so
/// that the pieces which break off or fall are added only once the
/// structure holds them. `None` when nothing could be moved, or when the
/// structure would hold them only in a step of more than
/// [`MAX_REPAIRED_STEP`] pieces, or more than [`MAX_WAITING`] pieces wait
/// at once, or a piece of the new order could not be
/// put in place after the pieces before it, or a deferred piece no longer
/// could after what is built (the verifier would refuse the order: the
/// walk stops there), or the deadline passed first.
pub fn reorder(
    assembly: &Assembly,
    params: &Params,
    first_failure: u32,
    deadline: Option<std::time::Instant>,
) -> Result<Option<Reordered>, PhysicsError> {
    let go = || deadline.is_none_or(|d| std::time::Instant::now() < d);
    reorder_while(assembly, params, first_failure, &go)
}

/// [`reorder`], going on while `go` says so (checked before each trial):
/// `None` once it does not.
pub fn reorder_while(
    assembly: &Assembly,
    params: &Params,
    first_failure: u32,
    go: &dyn Fn() -> bool,
) -> Result<Option<Reordered>, PhysicsError> {
    let started_at = std::time::Instant::now();
    let n = assembly.pieces.len();
    let bodies: Vec<_> = assembly
        .pieces
        .iter()
        .map(|p| p.placement.body(assembly.layer_ldu))
        .collect();
    let neighbours = crate::assembly::verify::connections(&bodies);
    // What is placed, for whether each piece of the new order can be put
    // in place after the pieces before it, and whether a deferred piece
    // still can be after what is built: once one cannot, the verifier
    // would refuse the new order, so the walk stops there.
    let mut placing = Placing::new(bodies.iter().map(|b| &b.bbox));
    // Pieces on the ground may start a part of their own, as the verifier
    // allows.
    let ground = bodies.iter().map(|b| b.bbox.min.z).min().unwrap_or(0);
    let on_ground: Vec<bool> = bodies.iter().map(|b| b.bbox.min.z == ground).collect();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, p) in assembly.pieces.iter().enumerate() {
        match groups.last_mut() {
            Some(g) if assembly.pieces[g[0]].step == p.step => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    let budget = SOLVES_PER_STEP * groups.len();
    let structure = Structure::new(assembly, params);
    let mut cert = Certifier::new(&structure, params);
    // The steps before the first failure stand: their equilibrium is
    // found first (none there: every step is analysed).
    let (mut started, mut certain) = (false, true);
    let mut trials = 0;
    let mut certified = 0;
    let mut placed: Vec<usize> = Vec::with_capacity(n);
    let mut is_placed = vec![false; n];
    let mut steps: Vec<Vec<usize>> = Vec::new();
    let mut deferred: BTreeSet<usize> = BTreeSet::new();
    let mut was_deferred = vec![false; n];
    let mut solves = 0;
    // Each piece's stress in the equilibrium kept, and the new steps'
    // checks made of them.
    let mut current = vec![PieceStress::falling(); n];
    let mut checks: Vec<StepCheck> = Vec::new();
    for group in groups {
        let step = assembly.pieces[group[0]].step.0;
        if step < first_failure {
            for &i in &group {
                placed.push(i);
                is_placed[i] = true;
                cert.place(i);
                placing.add(&bodies[i].bbox);
            }
            steps.push(group);
            continue;
        }
        if !started {
            started = true;
            let mut all = placed.clone();
            all.sort_unstable();
            certain = holds(&mut cert, &all, &mut current);
        }
        let mut trial: BTreeSet<usize> = deferred.iter().copied().chain(group).collect();
        let mut held: BTreeSet<usize> = BTreeSet::new();
        loop {
            let mut kept = connected(&trial, &is_placed, &on_ground, &neighbours);
            if kept.is_empty() {
                break;
            }
            // The step's own pieces first, then those it now holds.
            kept.sort_by_key(|&i| (was_deferred[i], i));
            if trials >= budget || !go() {
                return Ok(None);
            }
            trials += 1;
            // The kept equilibrium changed to hold the new pieces, if it
            // can be; else the analysis names the pieces that fail.
            let before = cert.forces().to_vec();
            for &i in &kept {
                cert.place(i);
            }
            let mut new = kept.clone();
            new.sort_unstable();
            let failing = if certain && holds(&mut cert, &new, &mut current) {
                certified += 1;
                Vec::new()
            } else {
                cert.set_forces(&before);
                for &i in &kept {
                    cert.remove(i);
                }
                solves += 1;
                // No certificate: expected to fail.
                let asm = subset(assembly, &placed, &kept);
                let analysis = analyze_expecting(&asm, params, First::Least)?;
                let failing = failing_new(&analysis, &placed, &kept, &neighbours);
                if failing.is_empty() {
                    // The analysis holds what no change to the kept
                    // equilibrium did: from here on, every step is
                    // analysed.
                    certain = false;
                    for &i in &kept {
                        cert.place(i);
                    }
                }
                failing
            };
            if failing.is_empty() {
                if kept.len() > MAX_REPAIRED_STEP {
                    return Ok(None);
                }
                for &i in &kept {
                    // Shut out by what is built before it in the new
                    // order: the verifier would refuse the order.
                    if !placing.placeable(&bodies[i].bbox) {
                        return Ok(None);
                    }
                    placed.push(i);
                    is_placed[i] = true;
                    trial.remove(&i);
                    placing.add(&bodies[i].bbox);
                }
                steps.push(kept);
                if certain {
                    let now: Vec<PieceStress> = placed.iter().map(|&i| current[i]).collect();
                    checks.push(check(steps.len() as u32, &now));
                }
                break;
            }
            for i in failing {
                trial.remove(&i);
                held.insert(i);
            }
        }
        trial.extend(held);
        for &i in &trial {
            was_deferred[i] = true;
        }
        // A deferred piece shut out by what is built (it comes after all
        // of it): the verifier would refuse the new order.
        if trial.iter().any(|&i| !placing.placeable(&bodies[i].bbox)) {
            return Ok(None);
        }
        // More pieces waiting than a repaired step may hold: the walk
        // gives up rather than carry them through the rest of the build
        // (see [`MAX_WAITING`]).
        if trial.len() > MAX_WAITING {
            return Ok(None);
        }
        deferred = trial;
    }
    // Certified at every step to the end, the walk is the new order's check.
    let walked = (certain && deferred.is_empty()).then(|| Walked {
        steps: checks,
        last: Analysis::new(
            placed.iter().map(|&i| current[i]).collect(),
            started_at.elapsed().as_secs_f64(),
        ),
    });
    if !deferred.is_empty() {
        // Whatever never stood is added at the end, as it was: the final
        // check reports it.
        let mut rest: Vec<usize> = deferred.into_iter().collect();
        while !rest.is_empty() {
            let set: BTreeSet<usize> = rest.iter().copied().collect();
            let kept = connected(&set, &is_placed, &on_ground, &neighbours);
            if kept.is_empty() {
                // Cannot happen for a verified build: every piece is on the
                // ground or joins the structure. Keep the pieces rather than
                // lose them.
                steps.push(std::mem::take(&mut rest));
                break;
            }
            if kept.len() > MAX_REPAIRED_STEP {
                return Ok(None);
            }
            for &i in &kept {
                if !placing.placeable(&bodies[i].bbox) {
                    return Ok(None);
                }
                placed.push(i);
                is_placed[i] = true;
                placing.add(&bodies[i].bbox);
            }
            rest.retain(|i| !is_placed[*i]);
            steps.push(kept);
        }
    }
    let mut moved = Vec::new();
    let mut pieces: Vec<Placed> = Vec::with_capacity(n);
    for (s, group) in steps.iter().enumerate() {
        let to = s as u32 + 1;
        for &i in group {
            let p = assembly.pieces[i];
            if was_deferred[i] {
                moved.push(Moved {
                    piece: i,
                    part: p.placement.part.spec().id.0,
                    from_step: p.step.0,
                    to_step: to,
                });
            }
            pieces.push(Placed {
                step: Step(to),
                ..p
            });
        }
    }
    if moved.is_empty() {
        return Ok(None);
    }
    moved.sort_by_key(|m| m.piece);
    Ok(Some(Reordered {
        assembly: Assembly {
            pieces,
            layer_ldu: assembly.layer_ldu,
        },
        moved,
        solves,
        certified,
        walked,
    }))
}

/// Whether every group of `cert`'s placed pieces that holds a piece of
/// `new` (sorted) stands, its kept equilibrium changed to hold them; if
/// so, their pieces' stresses in it go into `current`.
fn holds(cert: &mut Certifier, new: &[usize], current: &mut [PieceStress]) -> bool {
    let mut found = Vec::new();
    for (job, mine) in cert.groups_with(new) {
        if !job.grounded {
            return false;
        }
        match cert.certify(&job, &mine) {
            Verdict::Stands(stress) => found.push((job.pieces, stress)),
            _ => return false,
        }
    }
    for (pieces, stress) in found {
        for (p, st) in pieces.into_iter().zip(stress) {
            current[p] = st;
        }
    }
    true
}

/// The pieces of `trial` that join what is built, in order: each stands
/// on the ground or connects to a placed piece or to one kept before it.
/// Pieces that only connect through a later one are found by repeating
/// the pass.
fn connected(
    trial: &BTreeSet<usize>,
    is_placed: &[bool],
    on_ground: &[bool],
    neighbours: &[Vec<usize>],
) -> Vec<usize> {
    let mut kept: Vec<usize> = Vec::new();
    let mut in_kept = BTreeSet::new();
    loop {
        let before = kept.len();
        for &i in trial {
            if in_kept.contains(&i) {
                continue;
            }
            let joins = on_ground[i]
                || neighbours[i]
                    .iter()
                    .any(|&j| is_placed[j] || in_kept.contains(&j));
            if joins {
                kept.push(i);
                in_kept.insert(i);
            }
        }
        if kept.len() == before {
            return kept;
        }
    }
}

/// The placed pieces, then the kept ones, as one assembly to analyse.
fn subset(assembly: &Assembly, placed: &[usize], kept: &[usize]) -> Assembly {
    Assembly {
        pieces: placed
            .iter()
            .chain(kept)
            .map(|&i| assembly.pieces[i])
            .collect(),
        layer_ldu: assembly.layer_ldu,
    }
}

/// The new pieces to defer after `analysis` of placed ++ kept failed:
/// the new pieces that break off or fall; when only built pieces fail
/// (the new load broke them), the new pieces touching a failing one, or
/// else all new pieces. Empty when the structure stands.
fn failing_new(
    analysis: &Analysis,
    placed: &[usize],
    kept: &[usize],
    neighbours: &[Vec<usize>],
) -> Vec<usize> {
    let fails = |k: usize| {
        let p = &analysis.pieces[k];
        p.fails()
    };
    let n_old = placed.len();
    let new: Vec<usize> = (0..kept.len())
        .filter(|&k| fails(n_old + k))
        .map(|k| kept[k])
        .collect();
    if !new.is_empty() {
        return new;
    }
    let old: BTreeSet<usize> = (0..n_old)
        .filter(|&k| fails(k))
        .map(|k| placed[k])
        .collect();
    if old.is_empty() {
        return Vec::new();
    }
    let touching: Vec<usize> = kept
        .iter()
        .copied()
        .filter(|&i| neighbours[i].iter().any(|j| old.contains(j)))
        .collect();
    if touching.is_empty() {
        kept.to_vec()
    } else {
        touching
    }
}
