//! The bottom part, which nothing holds from below, generated forward.
//!
//! Backward tracing keeps what is left buildable with local checks; that is
//! enough where every piece can rest on the structure built below (every
//! part but the first), and not enough for the bottom layers, where the
//! pieces must interlock among themselves and whether the rest can still be
//! joined depends on a layout not yet chosen. There the same rewriting
//! system runs in its generative direction: a starting rule puts the first
//! piece in the middle, and each step applies a basic rule `A -> A + B` to a
//! piece `A` already placed, with rules sampled from their frequencies and
//! the same adaptive branching factor, depth first with backtracking. The
//! voxel nearest the first piece that is still uncovered is the one the next
//! piece must cover, so the build grows outward and stays connected by
//! construction. The result is handed on as the equivalent backward trace.

use std::collections::HashMap;
use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::dfs::PartResult;
use super::state::{face_fits, Anchor, Model, Removal, State};
use super::{SearchOptions, SearchStats};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Cell, CellBox, Rot};
use crate::grammar::RuleSet;
use crate::voxel::VoxelGrid;

const NONE: u32 = u32::MAX;

/// Seeds tried for the first piece before voxels are left out.
const MAX_SEEDS: usize = 16;

struct Frame {
    target: Cell,
    slots: Vec<u32>,
    slot: usize,
    corner: usize,
    widened: bool,
    /// Whether the look-ahead was switched off after every rule failed.
    relaxed: bool,
    placed: bool,
    /// For each new piece's shape tried so far, the placements over the
    /// target that fit the free voxels and can be pressed in: many rules
    /// share a shape, and the fit does not change while the frame lives.
    fits: HashMap<(PartKind, Rot), Vec<Placement>>,
}

/// Grows a build of `v` forward: from a starting piece near the middle of
/// its lowest layer when nothing is built yet, otherwise from the pieces
/// that rest on `built`, the structure built before. Voxels that no rule can
/// join after `max_backtracks_per_part` backtracks are left out of `v`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn grow(
    v: &mut VoxelGrid,
    built: &VoxelGrid,
    model: Model,
    rules: &RuleSet,
    opts: &SearchOptions,
    deadline: Instant,
    rng: &mut ChaCha8Rng,
    stats: &mut SearchStats,
) -> PartResult {
    let Some(bounds) = v.bounds() else {
        return PartResult::Built(Vec::new());
    };
    let (nx, ny, nz) = v.dims();
    let total = v.count();
    let mut backtracks_here = 0u64;
    let on_built = |c: Cell| built.get(c.offset(0, 0, -1)) || built.get(c.offset(0, 0, 1));
    // Growth starts next to the built structure, or in the middle of the
    // lowest layer.
    let (cx, cy) = (
        2 * bounds.min.x + bounds.sx - 1,
        2 * bounds.min.y + bounds.sy - 1,
    );
    let seeds: Vec<Cell> = if built.is_empty() {
        // Prefer a cell with a voxel above it, so the next piece can connect.
        let mut order: Vec<Cell> = v.layer_cells(bounds.min.z).collect();
        order.sort_by_key(|c| {
            let (dx, dy) = (2 * c.x - cx, 2 * c.y - cy);
            (!v.get(c.offset(0, 0, 1)), dx * dx + dy * dy, c.y, c.x)
        });
        order.truncate(MAX_SEEDS);
        order
    } else {
        v.cells().filter(|&c| on_built(c)).collect()
    };
    let dist = distances(v, &seeds);
    let by_layer = !built.is_empty() || bounds.sz > 2;
    let mut cover = VoxelGrid::new(nx, ny, nz);
    let mut owner = vec![NONE; v.len()];
    let mut placed: Vec<(Placement, Anchor, Option<crate::grammar::RuleId>)> = Vec::new();

    let starts = super::start_shapes(rules);
    let u = rules.layer_ldu();
    let place = |p: &Placement, cover: &mut VoxelGrid, owner: &mut Vec<u32>, id: u32| {
        let b = p.body(u);
        cover.set_body(&b, true);
        for c in b.cells() {
            let i = cover.index(c);
            owner[i] = id;
        }
    };
    // With nothing built, the starting rule puts the biggest starting piece
    // over the seed; if the growth from there is stuck before it ever leaves
    // the first piece, the next seed is tried.
    let mut seed_k = 0usize;
    if built.is_empty() {
        let Some(first) = start_at(v, &model, u, &starts, seeds[0]) else {
            return PartResult::Unbuildable;
        };
        place(&first, &mut cover, &mut owner, 0);
        placed.push((first, Anchor::Start, None));
        stats.starts += 1;
    }
    let n_rules = rules.variants().len() as u32;
    let weights: Vec<f64> = rules.variants().iter().map(|x| x.weight).collect();
    let mut by_shape: Vec<u32> = (0..n_rules).collect();
    by_shape.sort_by_key(|&i| {
        let x = &rules.variants()[i as usize];
        (
            std::cmp::Reverse(x.added.spec().studs()),
            x.added,
            x.added_rot,
            i,
        )
    });
    // Slots past the rules are starting pieces resting on the built part.
    if !built.is_empty() {
        by_shape.extend((0..starts.len() as u32).map(|k| n_rules + k));
    }
    let shapes = super::footprints(rules);
    let pieces: Vec<(PartKind, Rot)> = rules
        .alphabet()
        .iter()
        .flat_map(|&p| {
            Rot::ALL
                .into_iter()
                .filter(move |&r| p.spec().canonical_rot(r) == r)
                .map(move |r| (p, r))
        })
        .collect();
    let mut stack: Vec<Frame> = Vec::new();
    loop {
        let left = v.count() - cover.count();
        if left == 0 {
            let trace = placed
                .iter()
                .rev()
                .map(|&(p, a, r)| Removal::forward(p, a, r))
                .collect();
            return PartResult::Built(trace);
        }
        if Instant::now() >= deadline {
            return PartResult::OutOfBudget;
        }
        if stack.last().is_none_or(|f| f.placed) {
            let target = nearest_uncovered(v, &cover, built, by_layer, &dist);
            let done = 1.0 - left as f64 / total as f64;
            let b = (opts.b_min as f64 + (opts.b_max - opts.b_min) as f64 * done * done) as usize;
            let mut slots = sample(&weights, b, rng);
            if !built.is_empty() && on_built(target) {
                slots.extend((0..starts.len() as u32).map(|k| n_rules + k));
            }
            stack.push(Frame {
                target,
                slots,
                slot: 0,
                corner: 0,
                widened: false,
                relaxed: false,
                placed: false,
                fits: HashMap::new(),
            });
        }
        let at_root = stack.len() == 1;
        let f = stack.last_mut().expect("frame");
        let mut found: Option<(Placement, Anchor, Option<u32>)> = None;
        'scan: loop {
            while f.slot < f.slots.len() {
                let si = f.slots[f.slot];
                let (added, added_rot) = if si < n_rules {
                    let x = &rules.variants()[si as usize];
                    (x.added, x.added_rot)
                } else {
                    starts[(si - n_rules) as usize]
                };
                // Every way the piece can lie over the target voxel.
                let target = f.target;
                let fit = f
                    .fits
                    .entry((added, added_rot))
                    .or_insert_with(|| {
                        let local = added.body(added_rot, Cell::new(0, 0, 0), u);
                        local
                            .cells()
                            .map(|o| {
                                Placement::new(added, target.offset(-o.x, -o.y, -o.z), added_rot)
                            })
                            .filter(|p| {
                                let b = p.body(u);
                                if !v.all_set_body(&b)
                                    || cover.any_set_body(&b)
                                    || !face_fits(&model, built, p, &b)
                                {
                                    return false;
                                }
                                let ok = super::state::placeable(&cover, built, &b.bbox);
                                if !ok {
                                    stats.rejected_placeable += 1;
                                }
                                ok
                            })
                            .collect()
                    })
                    .clone();
                while f.corner < fit.len() {
                    let p = fit[f.corner];
                    f.corner += 1;
                    stats.match_tries += 1;
                    if stats.match_tries % 65_536 == 0 && Instant::now() >= deadline {
                        return PartResult::OutOfBudget;
                    }
                    let b = p.body(u);
                    let anchor = if si < n_rules {
                        let x = &rules.variants()[si as usize];
                        let (dx, dy, dz) = x.offset;
                        let a =
                            Placement::new(x.anchor, p.origin.offset(-dx, -dy, -dz), x.anchor_rot);
                        let key = a.body(u).key();
                        if !cover.in_bounds(key) {
                            continue;
                        }
                        let id = owner[v.index(key)];
                        if id == NONE || placed[id as usize].0 != a {
                            continue;
                        }
                        Anchor::Piece(a)
                    } else {
                        if !model.joins_built(&b) {
                            continue;
                        }
                        Anchor::Built
                    };
                    cover.set_body(&b, true);
                    let ok = f.relaxed || still_coverable(v, &cover, built, &b.bbox, &shapes);
                    cover.set_body(&b, false);
                    if !ok {
                        stats.rejected_reach += 1;
                        continue;
                    }
                    found = Some((
                        p,
                        anchor,
                        (si < n_rules).then(|| rules.variants()[si as usize].rule.0),
                    ));
                    break 'scan;
                }
                f.slot += 1;
                f.corner = 0;
            }
            if f.widened && f.relaxed {
                break;
            }
            if f.widened {
                // Every rule failed the look-ahead: cover the voxel even if
                // that may strand a neighbour, rather than give up here.
                f.relaxed = true;
                f.slots = by_shape.clone();
                f.slot = 0;
                f.corner = 0;
                continue;
            }
            let tried: std::collections::HashSet<u32> = f.slots.iter().copied().collect();
            f.slots = by_shape
                .iter()
                .copied()
                .filter(|i| !tried.contains(i))
                .collect();
            f.slot = 0;
            f.corner = 0;
            f.widened = true;
            stats.widened += 1;
        }
        match found {
            Some((p, anchor, rule)) => {
                let id = placed.len() as u32;
                place(&p, &mut cover, &mut owner, id);
                placed.push((p, anchor, rule.map(crate::grammar::RuleId)));
                if anchor == Anchor::Built {
                    stats.starts += 1;
                }
                f.placed = true;
                stats.nodes += 1;
                stats.max_depth = stats.max_depth.max(placed.len() as u64);
                // The child frame is made on the next turn.
            }
            None => {
                if built.is_empty() && at_root && placed.len() == 1 && seed_k + 1 < seeds.len() {
                    // Stuck right at the start: start elsewhere.
                    seed_k += 1;
                    let (p, _, _) = placed.pop().expect("the first piece");
                    cover.set_body(&p.body(u), false);
                    owner.iter_mut().for_each(|o| *o = NONE);
                    stack.clear();
                    if let Some(first) = start_at(v, &model, u, &starts, seeds[seed_k]) {
                        place(&first, &mut cover, &mut owner, 0);
                        placed.push((first, Anchor::Start, None));
                    }
                    continue;
                }
                let hopeless = !can_ever_cover(v, built, &model, u, f.target, &pieces);
                if backtracks_here >= opts.max_backtracks_per_part || at_root || hopeless {
                    // Repair: this voxel cannot be joined to the build in any
                    // way tried; leave it out and go on from here.
                    let t = f.target;
                    v.set(t, false);
                    stats.dropped_unbuildable += 1;
                    stack.pop();
                    continue;
                }
                // Dead end: undo the piece that led here and try its next option.
                stack.pop();
                stats.backtracks += 1;
                backtracks_here += 1;
                let (p, _, _) = placed.pop().expect("a placed piece per frame");
                let b = p.body(u);
                cover.set_body(&b, false);
                for c in b.cells() {
                    owner[v.index(c)] = NONE;
                }
                match stack.last_mut() {
                    Some(parent) => parent.placed = false,
                    None => {
                        // The piece came from the root frame of a part on a
                        // built structure: there is no parent frame.
                        if !built.is_empty() {
                            continue;
                        }
                        return PartResult::Unbuildable;
                    }
                }
            }
        }
    }
}

/// Whether some piece over `u` fits the part's voxels and has a voxel of the
/// part or of the built structure directly above or below: if not, no order
/// of building can ever join `u`.
fn can_ever_cover(
    v: &VoxelGrid,
    built: &VoxelGrid,
    model: &Model,
    layer_ldu: i32,
    u: Cell,
    pieces: &[(PartKind, Rot)],
) -> bool {
    pieces.iter().any(|&(part, rot)| {
        let local = part.body(rot, Cell::new(0, 0, 0), layer_ldu);
        let fits = local.cells().any(|o| {
            let b = local.moved(u.x - o.x, u.y - o.y, u.z - o.z);
            let p = Placement::new(part, b.bbox.min, rot);
            v.all_set_body(&b)
                && face_fits(model, built, &p, &b)
                && (State::links(v, &b) || State::links(built, &b))
        });
        fits
    })
}

/// The biggest starting piece that covers `seed` with its bottom layer and
/// fits the voxels.
fn start_at(
    v: &VoxelGrid,
    model: &Model,
    layer_ldu: i32,
    starts: &[(crate::catalog::PartKind, Rot)],
    seed: Cell,
) -> Option<Placement> {
    let nothing = VoxelGrid::new(1, 1, 1);
    for &(part, rot) in starts {
        let (sx, sy) = part.spec().footprint(rot);
        for oy in 0..sy {
            for ox in 0..sx {
                let p = Placement::new(part, seed.offset(-ox, -oy, 0), rot);
                let b = p.body(layer_ldu);
                if b.contains(seed) && v.all_set_body(&b) && face_fits(model, &nothing, &p, &b) {
                    return Some(p);
                }
            }
        }
    }
    None
}

/// Breadth-first distances from `seed` through face-adjacent voxels.
fn distances(v: &VoxelGrid, seeds: &[Cell]) -> Vec<u32> {
    let mut d = vec![u32::MAX; v.len()];
    let mut q = std::collections::VecDeque::new();
    for &s in seeds {
        d[v.index(s)] = 0;
        q.push_back(s);
    }
    while let Some(c) = q.pop_front() {
        let dc = d[v.index(c)];
        for n in super::hierarchy::neighbors6(c) {
            if v.get(n) && d[v.index(n)] == u32::MAX {
                d[v.index(n)] = dc + 1;
                q.push_back(n);
            }
        }
    }
    d
}

/// The next voxel to cover: among those with a placed piece directly above
/// or below (so some piece over it connects), the lowest, then the nearest to
/// the start; else the nearest of all.
fn nearest_uncovered(
    v: &VoxelGrid,
    cover: &VoxelGrid,
    built: &VoxelGrid,
    by_layer: bool,
    dist: &[u32],
) -> Cell {
    v.cells()
        .filter(|&c| !cover.get(c))
        .min_by_key(|&c| {
            let (up, down) = (c.offset(0, 0, 1), c.offset(0, 0, -1));
            let supported = cover.get(up) || cover.get(down) || built.get(up) || built.get(down);
            // Past two layers the build goes up layer by layer, so no voxel
            // is shut in between pieces above and below it.
            let layer = if by_layer { c.z } else { 0 };
            (
                !supported,
                layer,
                dist[v.index(c)],
                std::cmp::Reverse(c.z),
                c.y,
                c.x,
            )
        })
        .expect("an uncovered voxel")
}

/// Draws `b` distinct rule indices from the categorical distribution of
/// `weights` (Efraimidis–Spirakis keys), in the order drawn.
pub(crate) fn sample(weights: &[f64], b: usize, rng: &mut ChaCha8Rng) -> Vec<u32> {
    let mut keyed: Vec<(f64, u32)> = weights
        .iter()
        .enumerate()
        .map(|(i, &w)| (rng.gen_range(f64::EPSILON..1.0f64).ln() / w, i as u32))
        .collect();
    let b = b.min(keyed.len());
    if b < keyed.len() {
        keyed.select_nth_unstable_by(b, |a, c| c.0.total_cmp(&a.0));
        keyed.truncate(b);
    }
    keyed.sort_by(|a, c| c.0.total_cmp(&a.0).then(a.1.cmp(&c.1)));
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Whether every uncovered voxel near `b` can still be covered in some
/// order: a voxel can be covered once some piece over it, fitting the
/// uncovered voxels, has a voxel directly above or below that is covered,
/// or can itself be covered first (a fixpoint over a window around `b`;
/// voxels outside the window are assumed coverable).
fn still_coverable(
    v: &VoxelGrid,
    cover: &VoxelGrid,
    built: &VoxelGrid,
    b: &CellBox,
    shapes: &[(i32, i32)],
) -> bool {
    let w = CellBox {
        min: b.min.offset(-4, -4, -2),
        sx: b.sx + 8,
        sy: b.sy + 8,
        sz: b.sz + 4,
    };
    let cells: Vec<Cell> = w.cells().filter(|&c| v.get(c) && !cover.get(c)).collect();
    if cells.is_empty() {
        return true;
    }
    let local = |c: Cell| {
        let d = c.offset(-w.min.x, -w.min.y, -w.min.z);
        ((d.z * w.sy + d.y) * w.sx + d.x) as usize
    };
    let mut ok = vec![false; w.volume() as usize];
    let free = |bx: &CellBox| v.all_set(bx) && !cover.any_set(bx);
    let mut pending = cells;
    loop {
        let before = pending.len();
        pending.retain(|&u| {
            let support = |c: Cell| {
                built.get(c) || (v.get(c) && (cover.get(c) || !w.contains(c) || ok[local(c)]))
            };
            let coverable = CellBox::covering(u, shapes).any(|bx| {
                free(&bx)
                    && bx
                        .cells()
                        .any(|c| support(c.offset(0, 0, -1)) || support(c.offset(0, 0, 1)))
            });
            if coverable {
                ok[local(u)] = true;
            }
            !coverable
        });
        if pending.is_empty() {
            return true;
        }
        if pending.len() == before {
            return false;
        }
    }
}
