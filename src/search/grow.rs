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
//! construction. Once every `complex_every` nodes, one complex rule picked
//! with equal probability is tried first: its `u` pieces must all be placed
//! already, and its new pieces go in together, in their order, as one node
//! (undone together on backtracking). The result is handed on as the
//! equivalent backward trace.

use std::collections::HashMap;
use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::dfs::PartResult;
use super::state::{face_fits, Anchor, Model, Removal, State};
use super::{Dice, SearchOptions, SearchStats};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, CellBox, Rot};
use crate::grammar::{ComplexVariant, Link, RuleRef, RuleSet};
use crate::voxel::VoxelGrid;

const NONE: u32 = u32::MAX;

/// Seeds tried for the first piece before voxels are left out.
const MAX_SEEDS: usize = 16;

/// What one node may try over its target voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Slot {
    /// A basic rule's rotated variant, by index.
    Rule(u32),
    /// A starting piece resting on the structure built before, by index.
    OnBuilt(u32),
    /// A complex rule's rotated variant, by index.
    Complex(u32),
}

struct Frame {
    target: Cell,
    slots: Vec<Slot>,
    slot: usize,
    corner: usize,
    widened: bool,
    /// Whether the look-ahead was switched off after every rule failed.
    relaxed: bool,
    /// Pieces the node's current choice placed (0: none yet).
    placed: usize,
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
    rng: &mut Dice,
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
    let mut placed: Vec<Choice> = Vec::new();

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
    let mut by_shape: Vec<Slot> = {
        let mut order: Vec<u32> = (0..n_rules).collect();
        order.sort_by_key(|&i| {
            let x = &rules.variants()[i as usize];
            (
                std::cmp::Reverse(x.added.spec().studs()),
                x.added,
                x.added_rot,
                i,
            )
        });
        order.into_iter().map(Slot::Rule).collect()
    };
    // Starting pieces resting on the built part come after the rules.
    if !built.is_empty() {
        by_shape.extend((0..starts.len() as u32).map(Slot::OnBuilt));
    }
    let complex = complex_groups(rules);
    let mut frames_made = 0u64;
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
        if stack.last().is_none_or(|f| f.placed > 0) {
            let target = nearest_uncovered(v, &cover, built, by_layer, &dist);
            let done = 1.0 - left as f64 / total as f64;
            let b = (opts.b_min as f64 + (opts.b_max - opts.b_min) as f64 * done * done) as usize;
            frames_made += 1;
            let mut slots: Vec<Slot> = Vec::new();
            // Once every k nodes, one complex rule, picked with equal
            // probability, is tested before the sampled basic rules.
            let k = u64::from(opts.complex_every);
            if k > 0 && !complex.is_empty() && frames_made % k == 0 {
                let pick = rng.complex.gen_range(0..complex.len());
                slots.extend(complex[pick].clone().map(Slot::Complex));
                stats.complex_tried += 1;
            }
            slots.extend(
                sample(&weights, b, &mut rng.rules)
                    .into_iter()
                    .map(Slot::Rule),
            );
            if !built.is_empty() && on_built(target) {
                slots.extend((0..starts.len() as u32).map(Slot::OnBuilt));
            }
            stack.push(Frame {
                target,
                slots,
                slot: 0,
                corner: 0,
                widened: false,
                relaxed: false,
                placed: 0,
                fits: HashMap::new(),
            });
        }
        let at_root = stack.len() == 1;
        let f = stack.last_mut().expect("frame");
        let mut found: Vec<Choice> = Vec::new();
        'scan: loop {
            while f.slot < f.slots.len() {
                let slot = f.slots[f.slot];
                if let Slot::Complex(ci) = slot {
                    let var = &rules.complex_variants()[ci as usize];
                    let corners: usize = var
                        .v
                        .iter()
                        .map(|n| n.piece.body(Cell::new(0, 0, 0), u).volume() as usize)
                        .sum();
                    while f.corner < corners {
                        // The corner-th cell of the new pieces, in order,
                        // goes on the target voxel.
                        let c = nth_new_cell(var, f.corner, u);
                        f.corner += 1;
                        stats.match_tries += 1;
                        if stats.match_tries % 65_536 == 0 && Instant::now() >= deadline {
                            return PartResult::OutOfBudget;
                        }
                        let grids = Grids {
                            v,
                            cover: &mut cover,
                            built,
                            model: &model,
                            owner: &owner,
                            placed: &placed,
                            layer_ldu: u,
                        };
                        let origin = f.target.offset(-c.x, -c.y, -c.z);
                        if let Some(pieces) =
                            match_complex(grids, var, origin, f.relaxed, &shapes, stats)
                        {
                            found = pieces;
                            break 'scan;
                        }
                    }
                    f.slot += 1;
                    f.corner = 0;
                    continue;
                }
                let (added, added_rot) = match slot {
                    Slot::Rule(i) => {
                        let x = &rules.variants()[i as usize];
                        (x.added, x.added_rot)
                    }
                    Slot::OnBuilt(k) => starts[k as usize],
                    Slot::Complex(_) => unreachable!("complex slots are handled above"),
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
                    let (anchor, rule) = if let Slot::Rule(i) = slot {
                        let x = &rules.variants()[i as usize];
                        let (dx, dy, dz) = x.offset;
                        let a =
                            Placement::new(x.anchor, p.origin.offset(-dx, -dy, -dz), x.anchor_rot);
                        if owner_of(&owner, &placed, v, &a.body(u)) != Some(a) {
                            continue;
                        }
                        (Anchor::Piece(a), Some(RuleRef::Basic(x.rule)))
                    } else {
                        if !model.joins_built(&b) {
                            continue;
                        }
                        (Anchor::Built, None)
                    };
                    cover.set_body(&b, true);
                    let ok = f.relaxed || still_coverable(v, &cover, built, &b.bbox, &shapes);
                    cover.set_body(&b, false);
                    if !ok {
                        stats.rejected_reach += 1;
                        continue;
                    }
                    found.push((p, anchor, rule));
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
            let tried: std::collections::HashSet<Slot> = f.slots.iter().copied().collect();
            f.slots = by_shape
                .iter()
                .copied()
                .filter(|s| !tried.contains(s))
                .collect();
            f.slot = 0;
            f.corner = 0;
            f.widened = true;
            stats.widened += 1;
        }
        if !found.is_empty() {
            if matches!(found[0].2, Some(RuleRef::Complex(_))) {
                stats.complex_applied += 1;
            }
            f.placed = found.len();
            for (p, anchor, rule) in found {
                let id = placed.len() as u32;
                place(&p, &mut cover, &mut owner, id);
                placed.push((p, anchor, rule));
                if anchor == Anchor::Built {
                    stats.starts += 1;
                }
            }
            stats.nodes += 1;
            stats.max_depth = stats.max_depth.max(placed.len() as u64);
            // The child frame is made on the next turn.
            continue;
        }
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
        // Dead end: undo the pieces that led here (all the new pieces of a
        // complex rule together) and try the parent's next option.
        stack.pop();
        stats.backtracks += 1;
        backtracks_here += 1;
        let n = stack.last().map_or(1, |p| p.placed);
        for _ in 0..n {
            let (p, _, _) = placed.pop().expect("a placed piece per frame");
            let b = p.body(u);
            cover.set_body(&b, false);
            for c in b.cells() {
                owner[v.index(c)] = NONE;
            }
        }
        match stack.last_mut() {
            Some(parent) => parent.placed = 0,
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

/// A placed piece, what it is attached to, and the rule that added it.
type Choice = (Placement, Anchor, Option<RuleRef>);

/// The grids and pieces of a growth, for matching a complex rule.
struct Grids<'a> {
    v: &'a VoxelGrid,
    cover: &'a mut VoxelGrid,
    built: &'a VoxelGrid,
    model: &'a Model<'a>,
    owner: &'a [u32],
    placed: &'a [Choice],
    layer_ldu: i32,
}

/// The placed piece that holds the key cell of `b`, if any.
fn owner_of(owner: &[u32], placed: &[Choice], v: &VoxelGrid, b: &Body) -> Option<Placement> {
    let key = b.key();
    if !v.in_bounds(key) {
        return None;
    }
    let id = owner[v.index(key)];
    (id != NONE).then(|| placed[id as usize].0)
}

/// The variant indices of each complex rule.
fn complex_groups(rules: &RuleSet) -> Vec<std::ops::Range<u32>> {
    let mut out: Vec<std::ops::Range<u32>> = Vec::new();
    for (i, var) in rules.complex_variants().iter().enumerate() {
        let i = i as u32;
        match out.last_mut() {
            Some(r) if rules.complex_variants()[r.start as usize].rule == var.rule => r.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

/// The `k`-th cell of the new pieces of `var`, in order, with its first
/// `u` piece at the origin.
fn nth_new_cell(var: &ComplexVariant, mut k: usize, layer_ldu: i32) -> Cell {
    for n in &var.v {
        let b = n.piece.body(Cell::new(0, 0, 0), layer_ldu);
        let cells = b.volume() as usize;
        if k < cells {
            return b.cells().nth(k).expect("a cell of the body");
        }
        k -= cells;
    }
    unreachable!("k is less than the new pieces' volume")
}

/// The complex variant `var` with its first `u` piece at `origin`, if it
/// applies: every `u` piece is a placed piece, every new piece fits
/// uncovered voxels with its sloping face clear and can be pressed into
/// place after the ones before it, and (unless `relaxed`) every voxel near
/// them can still be covered. Returns the new pieces in order, each
/// anchored to the piece it stud-connects to.
fn match_complex(
    g: Grids<'_>,
    var: &ComplexVariant,
    origin: Cell,
    relaxed: bool,
    shapes: &[(i32, i32)],
    stats: &mut SearchStats,
) -> Option<Vec<Choice>> {
    let at = |p: &crate::grammar::complex::VariantPiece| {
        Placement::new(p.part, origin.offset(p.at.x, p.at.y, p.at.z), p.rot)
    };
    let mut olds: Vec<Placement> = Vec::with_capacity(var.u.len());
    for p in &var.u {
        let a = at(p);
        if owner_of(g.owner, g.placed, g.v, &a.body(g.layer_ldu)) != Some(a) {
            return None;
        }
        olds.push(a);
    }
    let news: Vec<(Placement, Body)> = var
        .v
        .iter()
        .map(|n| {
            let p = at(&n.piece);
            (p, p.body(g.layer_ldu))
        })
        .collect();
    if !news.iter().all(|(p, b)| {
        g.v.all_set_body(b) && !g.cover.any_set_body(b) && face_fits(g.model, g.built, p, b)
    }) {
        return None;
    }
    // A new piece pressed on top of its anchor may not roof over voxels
    // still to cover: the growth covers the lowest voxels first, and a
    // piece the rule lays ahead of it (running bond's far half) would leave
    // them to be slid in sideways, which is seldom possible.
    let body = |l: Link| match l {
        Link::U(k) => olds[k].body(g.layer_ldu),
        Link::V(k) => news[k].1,
    };
    for (n, (_, b)) in var.v.iter().zip(&news) {
        if body(n.anchor).holds(b) {
            let under = b.under_tubes();
            let open = under
                .cells()
                .any(|c| g.v.get(c) && !g.cover.get(c) && !news.iter().any(|(_, o)| o.contains(c)));
            if open {
                return None;
            }
        }
    }
    // Each new piece must go in with the ones before it in place.
    let mut placeable = true;
    let mut set = 0;
    for (_, b) in &news {
        if !super::state::placeable(g.cover, g.built, &b.bbox) {
            placeable = false;
            break;
        }
        g.cover.set_body(b, true);
        set += 1;
    }
    let ok = placeable
        && (relaxed || {
            let all = news
                .iter()
                .map(|(_, b)| b.bbox)
                .reduce(|a, b| a.union(&b))
                .expect("a new piece");
            still_coverable(g.v, g.cover, g.built, &all, shapes)
        });
    for (_, b) in &news[..set] {
        g.cover.set_body(b, false);
    }
    if !placeable {
        stats.rejected_placeable += 1;
        return None;
    }
    if !ok {
        stats.rejected_reach += 1;
        return None;
    }
    let rule = Some(RuleRef::Complex(var.rule));
    Some(
        var.v
            .iter()
            .zip(&news)
            .map(|(n, &(p, _))| {
                let anchor = match n.anchor {
                    Link::U(k) => olds[k],
                    Link::V(k) => news[k].0,
                };
                (p, Anchor::Piece(anchor), rule)
            })
            .collect(),
    )
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
