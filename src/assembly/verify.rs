//! The independent verifier: checks an [`Assembly`] against the rules a
//! real build must obey, without using any of the search's code.
//!
//! The search is clever and therefore easy to get subtly wrong; this module
//! is deliberately plain, so that it can be the check on the search. It
//! recomputes everything from the placements alone with sets of cells and a
//! breadth-first search, clarity over speed.
//!
//! # The rules
//!
//! A piece fills the cells of its [`Placement::body`] and takes up the space
//! of the body's bounding box (a slope's sloping face passes through the
//! cells of its box it does not fill). For the pieces in build order
//! (`asm.pieces`):
//!
//! - **No overlap**: no two pieces' bounding boxes share a cell
//!   ([`Failure::Overlap`]).
//! - **Stud connection**: piece A is connected to piece B when B's bottom
//!   rests on A's top and some of A's studs (a slope has studs on its back
//!   row only) meet B's underside where it takes studs (an inverted slope
//!   only under its back row), or the reverse. Every piece after the first must be connected to
//!   at least one *earlier* piece or stand on the ground, the build's lowest
//!   layer, as a person starts another part of the model on the table
//!   ([`Failure::NotConnected`]); and the finished build's connection graph
//!   must be one component ([`Failure::Disconnected`]).
//! - **Cover**: given a target voxel grid, the union of the cells the pieces
//!   fill equals its filled cells exactly ([`Failure::CoverMismatch`]).
//! - **Placeable at its turn** ([`Failure::NotPlaceable`]): let `O` be the
//!   cells of all earlier pieces. The piece can be brought in from outside
//!   iff, starting at its position, a breadth-first search over integer
//!   translations of its box reaches a position whose box lies entirely
//!   outside the bounding box of `O` (trivially so when `O` is empty).
//!   A position is *free* when its box meets no cell of `O`. Moves go between
//!   free positions: up or down one layer freely; sideways one stud only if,
//!   at both ends, the layer just above and the layer just below the box
//!   (over its footprint) hold no cell of `O` — the studs need half a voxel
//!   of clearance, rounded to the grid, to slide. First a fast path: if the
//!   footprint's column straight above the piece (up to the top of `O`) or
//!   straight below it (down to the bottom of `O`) is empty, the piece is
//!   placeable by a straight vertical move. A piece that overlaps an earlier
//!   one is reported as an overlap only.
//! - **Never inside a closed cavity** ([`Failure::Enclosed`]): the cells of
//!   the piece's box must be joined, through cells no earlier piece takes
//!   (face to face), to the space around the build: beside its bounding
//!   box or over it, never under the build's lowest layer, which stands on
//!   the table. The placeability search may pass below the ground, as a
//!   piece goes in under an overhang; this rule keeps a hollow model's
//!   inside from being built after its shell closes over it.
//!
//! # Example
//!
//! ```
//! use brickwright::assembly::{verify::verify, Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::geom::{Cell, Rot};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(2, 0, 1), Rot::R0),
//! ];
//! let report = verify(&Assembly::from_order(&order, 24, Color::RED), None);
//! assert!(report.is_ok(), "{report}");
//! ```

use std::collections::{HashMap, HashSet, VecDeque};
use std::fmt;

use crate::assembly::{Assembly, Step};
use crate::geom::{Body, Cell, CellBox};
use crate::voxel::VoxelGrid;

#[cfg(doc)]
use crate::assembly::Placement;

/// One broken rule. Piece numbers are indices into `asm.pieces`, from 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Failure {
    /// Pieces `a < b` share `cell` (the first shared cell of `b`'s box,
    /// reported once per pair, for at most 8 earlier pieces `a` a piece).
    Overlap {
        /// The earlier piece.
        a: usize,
        /// The later piece.
        b: usize,
        /// A cell both fill.
        cell: Cell,
    },
    /// The piece is stud-connected to no earlier piece and does not stand
    /// on the ground.
    NotConnected {
        /// The piece.
        piece: usize,
        /// Its step.
        step: Step,
    },
    /// The earlier pieces enclose the piece: it cannot be moved into place.
    NotPlaceable {
        /// The piece.
        piece: usize,
        /// Its step.
        step: Step,
    },
    /// Earlier pieces close a cavity around the piece: no path of empty
    /// cells joins it to the space around the build.
    Enclosed {
        /// The piece.
        piece: usize,
        /// Its step.
        step: Step,
    },
    /// The pieces' cells differ from the target's filled cells.
    CoverMismatch {
        /// Target cells no piece fills.
        missing: usize,
        /// Piece cells outside the target.
        extra: usize,
        /// The lowest differing cell (by layer, then row, then column).
        first: Cell,
    },
    /// The connection graph falls apart into this many components.
    Disconnected {
        /// Number of components (at least 2).
        components: usize,
    },
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = |c: &Cell| format!("({}, {}, {})", c.x, c.y, c.z);
        match self {
            Failure::Overlap { a, b, cell } => {
                write!(f, "pieces #{a} and #{b} overlap at cell {}", at(cell))
            }
            Failure::NotConnected { piece, step } => write!(
                f,
                "piece #{piece} (step {}) is not stud-connected to any earlier piece, nor on the ground",
                step.0
            ),
            Failure::NotPlaceable { piece, step } => write!(
                f,
                "piece #{piece} (step {}) cannot be put in place: earlier pieces enclose it",
                step.0
            ),
            Failure::Enclosed { piece, step } => write!(
                f,
                "piece #{piece} (step {}) is placed inside a closed cavity: earlier pieces shut it in on every side",
                step.0
            ),
            Failure::CoverMismatch {
                missing,
                extra,
                first,
            } => write!(
                f,
                "the pieces do not cover the target: {missing} cells missing, {extra} extra, \
                 first difference at {}",
                at(first)
            ),
            Failure::Disconnected { components } => {
                write!(f, "the build falls apart into {components} separate parts")
            }
        }
    }
}

/// How many failures a [`VerifyReport`] shows; the rest are counted.
pub const SHOWN_FAILURES: usize = 20;

/// Everything [`verify`] found wrong; empty when the assembly is sound.
/// It displays the first [`SHOWN_FAILURES`] and a count of the rest.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VerifyReport {
    /// The failures: overlaps first, then per piece in build order, then the
    /// whole-build checks.
    pub failures: Vec<Failure>,
}

impl VerifyReport {
    /// Whether no rule is broken.
    pub fn is_ok(&self) -> bool {
        self.failures.is_empty()
    }
}

impl fmt::Display for VerifyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_ok() {
            return write!(f, "assembly verified: no failures");
        }
        write!(f, "{} verification failure(s):", self.failures.len())?;
        for failure in self.failures.iter().take(SHOWN_FAILURES) {
            write!(f, "\n  - {failure}")?;
        }
        if self.failures.len() > SHOWN_FAILURES {
            write!(
                f,
                "\n  ... and {} more",
                self.failures.len() - SHOWN_FAILURES
            )?;
        }
        Ok(())
    }
}

/// Checks `asm` against every rule of the module docs, and its cover against
/// `target` when given.
pub fn verify(asm: &Assembly, target: Option<&VoxelGrid>) -> VerifyReport {
    let bodies: Vec<Body> = asm
        .pieces
        .iter()
        .map(|p| p.placement.body(asm.layer_ldu))
        .collect();
    let boxes: Vec<CellBox> = bodies.iter().map(|b| b.bbox).collect();
    let steps: Vec<Step> = asm.pieces.iter().map(|p| p.step).collect();
    let mut failures = check_overlaps(&boxes);
    let overlapping: HashSet<usize> = failures
        .iter()
        .filter_map(|f| match f {
            Failure::Overlap { b, .. } => Some(*b),
            _ => None,
        })
        .collect();

    let neighbours = connections(&bodies);
    let mut occupied = Occupied::new(&boxes);
    let ground = boxes.iter().map(|b| b.min.z).min().unwrap_or(0);
    for (i, b) in boxes.iter().enumerate() {
        if i > 0 && b.min.z != ground && !neighbours[i].iter().any(|&j| j < i) {
            failures.push(Failure::NotConnected {
                piece: i,
                step: steps[i],
            });
        }
        if !overlapping.contains(&i) && !placeable(b, &occupied) {
            failures.push(Failure::NotPlaceable {
                piece: i,
                step: steps[i],
            });
        }
        occupied.add(b);
    }
    // One failure a piece: one that cannot move at all is not also shut in.
    let stuck: HashSet<usize> = failures
        .iter()
        .filter_map(|f| match f {
            Failure::Overlap { b, .. } => Some(*b),
            Failure::NotPlaceable { piece, .. } => Some(*piece),
            _ => None,
        })
        .collect();
    failures.extend(
        enclosed(&boxes, &stuck)
            .into_iter()
            .map(|i| Failure::Enclosed {
                piece: i,
                step: steps[i],
            }),
    );

    let components = count_components(&neighbours);
    if components > 1 {
        failures.push(Failure::Disconnected { components });
    }
    if let Some(target) = target {
        failures.extend(check_cover(&bodies, target));
    }
    VerifyReport { failures }
}

/// At most this many earlier pieces are named for one overlapping piece,
/// and this many owners are remembered for one cell: a sound or nearly
/// sound build never comes close, and a file stacking thousands of pieces
/// on one spot is checked in linear time instead of pair by pair.
const MAX_OVERLAPS_PER_PIECE: usize = 8;

/// Pairs of pieces sharing a cell, with the first shared cell of the later
/// piece; for each later piece, at most [`MAX_OVERLAPS_PER_PIECE`] earlier
/// ones.
fn check_overlaps(boxes: &[CellBox]) -> Vec<Failure> {
    let mut owners: HashMap<Cell, Vec<usize>> = HashMap::new();
    let mut failures = Vec::new();
    let mut named: Vec<usize> = Vec::new();
    for (b, bx) in boxes.iter().enumerate() {
        named.clear();
        for cell in bx.cells() {
            let here = owners.entry(cell).or_default();
            for &a in here.iter() {
                if named.len() < MAX_OVERLAPS_PER_PIECE && !named.contains(&a) {
                    named.push(a);
                    failures.push(Failure::Overlap { a, b, cell });
                }
            }
            if here.len() < MAX_OVERLAPS_PER_PIECE {
                here.push(b);
            }
        }
    }
    failures
}

/// Every pair `(below, above)` of pieces where `above`'s bottom layer lies
/// right on `below`'s top layer and their footprints overlap: the pairs
/// that can touch face to face, whether or not studs meet. Sorted by
/// `below`, then `above`. [`connections`] keeps those where studs meet
/// tubes; the physics stage also uses the others (compression only).
///
/// Found through the cells under each piece, so the time grows with the
/// pieces' footprints, not with the square of the pieces in a layer. A
/// cell remembers the first `MAX_OVERLAPS_PER_PIECE` (8) pieces whose bottom
/// covers it: in a build without overlaps there is one at most, and a file
/// stacking thousands of copies on one spot (each an overlap already) gives
/// a bounded number of pairs instead of the square of the copies.
pub fn stacked_pairs(bodies: &[Body]) -> Vec<(usize, usize)> {
    // The pieces whose bounding box's bottom layer covers each cell.
    let mut bottoms: HashMap<Cell, Vec<usize>> = HashMap::new();
    for (i, b) in bodies.iter().enumerate() {
        let bx = &b.bbox;
        for y in bx.min.y..bx.min.y + bx.sy {
            for x in bx.min.x..bx.min.x + bx.sx {
                let here = bottoms.entry(Cell::new(x, y, bx.min.z)).or_default();
                if here.len() < MAX_OVERLAPS_PER_PIECE {
                    here.push(i);
                }
            }
        }
    }
    let mut pairs = Vec::new();
    let mut above: Vec<usize> = Vec::new();
    for (below, a) in bodies.iter().enumerate() {
        let bx = &a.bbox;
        let top = bx.max_excl().z;
        above.clear();
        for y in bx.min.y..bx.min.y + bx.sy {
            for x in bx.min.x..bx.min.x + bx.sx {
                if let Some(on) = bottoms.get(&Cell::new(x, y, top)) {
                    above.extend(on);
                }
            }
        }
        above.sort_unstable();
        above.dedup();
        pairs.extend(above.iter().map(|&i| (below, i)));
    }
    pairs
}

/// For each piece, the pieces it is stud-connected to (resting on its studs
/// or holding it on theirs): the [`stacked_pairs`] where [`Body::holds`].
pub fn connections(bodies: &[Body]) -> Vec<Vec<usize>> {
    let mut neighbours = vec![Vec::new(); bodies.len()];
    for (below, above) in stacked_pairs(bodies) {
        if bodies[below].holds(&bodies[above]) {
            neighbours[below].push(above);
            neighbours[above].push(below);
        }
    }
    neighbours
}

/// Number of stud-connected components of `asm`: 1 for a build that holds
/// together, 0 for no pieces.
pub fn components(asm: &Assembly) -> usize {
    let bodies: Vec<Body> = asm
        .pieces
        .iter()
        .map(|p| p.placement.body(asm.layer_ldu))
        .collect();
    count_components(&connections(&bodies))
}

/// Number of connected components of the graph (0 for no pieces).
fn count_components(neighbours: &[Vec<usize>]) -> usize {
    let mut seen = vec![false; neighbours.len()];
    let mut components = 0;
    for start in 0..neighbours.len() {
        if seen[start] {
            continue;
        }
        components += 1;
        seen[start] = true;
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            for &j in &neighbours[i] {
                if !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
    }
    components
}

/// The cover check: union of piece cells against the target's cells.
fn check_cover(bodies: &[Body], target: &VoxelGrid) -> Option<Failure> {
    let filled: HashSet<Cell> = bodies.iter().flat_map(|b| b.cells()).collect();
    let missing: Vec<Cell> = target.cells().filter(|c| !filled.contains(c)).collect();
    let extra: Vec<Cell> = filled.iter().copied().filter(|&c| !target.get(c)).collect();
    let first = missing
        .iter()
        .chain(&extra)
        .min_by_key(|c| (c.z, c.y, c.x))?;
    Some(Failure::CoverMismatch {
        missing: missing.len(),
        extra: extra.len(),
        first: *first,
    })
}

/// The cells of the pieces placed so far, with their bounding box: a
/// dense grid over the boxes of every piece that may be added.
#[derive(Debug)]
struct Occupied {
    /// The grid's minimum corner and size.
    origin: Cell,
    dims: (i32, i32, i32),
    taken: Vec<bool>,
    /// Inclusive minimum and maximum corners of the cells taken; `None`
    /// while empty.
    bounds: Option<(Cell, Cell)>,
}

impl Occupied {
    /// Nothing taken yet, in a grid over the boxes `all` (those that may
    /// be added).
    fn new<'a>(all: impl IntoIterator<Item = &'a CellBox>) -> Occupied {
        let mut ext: Option<(Cell, Cell)> = None;
        for b in all {
            let m = b.max_excl();
            ext = Some(match ext {
                None => (b.min, m),
                Some((l, h)) => (lowest(l, b.min), highest(h, m)),
            });
        }
        let (origin, hi) = ext.unwrap_or((Cell::new(0, 0, 0), Cell::new(0, 0, 0)));
        let dims = (hi.x - origin.x, hi.y - origin.y, hi.z - origin.z);
        Occupied {
            origin,
            dims,
            taken: vec![false; (dims.0 * dims.1 * dims.2).max(0) as usize],
            bounds: None,
        }
    }

    /// The part of `b` within the grid, as index ranges, or `None`.
    fn clip(&self, b: &CellBox) -> Option<[std::ops::Range<i32>; 3]> {
        let o = self.origin;
        let (nx, ny, nz) = self.dims;
        let r = |lo: i32, len: i32, n: i32| (lo.max(0))..((lo + len).min(n));
        let ranges = [
            r(b.min.x - o.x, b.sx, nx),
            r(b.min.y - o.y, b.sy, ny),
            r(b.min.z - o.z, b.sz, nz),
        ];
        ranges.iter().all(|r| !r.is_empty()).then_some(ranges)
    }

    fn add(&mut self, b: &CellBox) {
        let (nx, ny, _) = self.dims;
        if let Some([xs, ys, zs]) = self.clip(b) {
            for z in zs {
                for y in ys.clone() {
                    for x in xs.clone() {
                        self.taken[((z * ny + y) * nx + x) as usize] = true;
                    }
                }
            }
        }
        let hi = b.max_excl().offset(-1, -1, -1);
        self.bounds = Some(match self.bounds {
            None => (b.min, hi),
            Some((l, h)) => (lowest(l, b.min), highest(h, hi)),
        });
    }

    /// Whether any cell of `b` is occupied (an empty box has none).
    fn any_in(&self, b: &CellBox) -> bool {
        let (nx, ny, _) = self.dims;
        let Some([xs, ys, zs]) = self.clip(b) else {
            return false;
        };
        zs.into_iter().any(|z| {
            ys.clone().any(|y| {
                let row = ((z * ny + y) * nx) as usize;
                self.taken[row + xs.start as usize..row + xs.end as usize].contains(&true)
            })
        })
    }
}

/// The corner of the lowest coordinates of `a` and `b`.
fn lowest(a: Cell, b: Cell) -> Cell {
    Cell::new(a.x.min(b.x), a.y.min(b.y), a.z.min(b.z))
}

/// The corner of the highest coordinates of `a` and `b`.
fn highest(a: Cell, b: Cell) -> Cell {
    Cell::new(a.x.max(b.x), a.y.max(b.y), a.z.max(b.z))
}

/// The pieces (but those in `skip`) whose box, at their turn,
/// no path of free cells joins to the space around the build.
///
/// Taken in reverse build order, the free space only grows: each piece
/// taken away frees its cells, and a flood from the outside spreads into
/// them when they touch it. Every cell is flooded once, so the check costs
/// the build's bounding box and the pieces' boxes, not their product.
fn enclosed(boxes: &[CellBox], skip: &HashSet<usize>) -> Vec<usize> {
    let Some(first) = boxes.first() else {
        return Vec::new();
    };
    let (mut lo, mut hi) = (first.min, first.max_excl());
    for b in boxes {
        let m = b.max_excl();
        lo = Cell::new(lo.x.min(b.min.x), lo.y.min(b.min.y), lo.z.min(b.min.z));
        hi = Cell::new(hi.x.max(m.x), hi.y.max(m.y), hi.z.max(m.z));
    }
    // One free cell around the sides and over the top; none under the
    // lowest layer (the table).
    let origin = lo.offset(-1, -1, 0);
    let (nx, ny, nz) = (hi.x - lo.x + 2, hi.y - lo.y + 2, hi.z - lo.z + 1);
    let index = |c: Cell| {
        let (x, y, z) = (c.x - origin.x, c.y - origin.y, c.z - origin.z);
        (x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz)
            .then(|| ((z * ny + y) * nx + x) as usize)
    };
    let border = |c: Cell| {
        c.x == origin.x
            || c.y == origin.y
            || c.x == origin.x + nx - 1
            || c.y == origin.y + ny - 1
            || c.z == origin.z + nz - 1
    };
    let mut taken = vec![0u32; (nx * ny * nz) as usize];
    for b in boxes {
        for c in b.cells() {
            if let Some(i) = index(c) {
                taken[i] += 1;
            }
        }
    }
    let mut outside = vec![false; taken.len()];
    let mut queue: Vec<Cell> = Vec::new();
    let flood = |queue: &mut Vec<Cell>, outside: &mut Vec<bool>, taken: &[u32]| {
        while let Some(c) = queue.pop() {
            for (dx, dy, dz) in crate::geom::FACES {
                let n = c.offset(dx, dy, dz);
                if let Some(i) = index(n) {
                    if taken[i] == 0 && !outside[i] {
                        outside[i] = true;
                        queue.push(n);
                    }
                }
            }
        }
    };
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let c = origin.offset(x, y, z);
                if border(c) {
                    if let Some(i) = index(c) {
                        outside[i] = true;
                        queue.push(c);
                    }
                }
            }
        }
    }
    flood(&mut queue, &mut outside, &taken);
    let mut shut = Vec::new();
    for (k, b) in boxes.iter().enumerate().rev() {
        for c in b.cells() {
            if let Some(i) = index(c) {
                taken[i] -= 1;
            }
        }
        // Freed cells beside the outside join it, and so does what they
        // open onto.
        for c in b.cells() {
            let Some(i) = index(c) else { continue };
            if taken[i] > 0 || outside[i] {
                continue;
            }
            let touches = crate::geom::FACES
                .iter()
                .any(|&(dx, dy, dz)| index(c.offset(dx, dy, dz)).is_some_and(|j| outside[j]));
            if touches {
                outside[i] = true;
                queue.push(c);
                flood(&mut queue, &mut outside, &taken);
            }
        }
        if !skip.contains(&k) && !b.cells().any(|c| index(c).is_some_and(|i| outside[i])) {
            shut.push(k);
        }
    }
    shut.reverse();
    shut
}

/// The box `b` moved to minimum corner `min`.
fn moved(b: &CellBox, min: Cell) -> CellBox {
    CellBox { min, ..*b }
}

/// The pieces put in place so far, for asking whether another can still
/// be put in place after them by the placeability rule of the module docs
/// (as [`verify`] asks it). More pieces never make a piece placeable
/// again: its free positions only shrink and the space it must reach only
/// moves away.
pub(crate) struct Placing(Occupied);

impl Placing {
    /// Nothing placed yet, of the pieces `all` (those that may be added).
    pub(crate) fn new<'a>(all: impl IntoIterator<Item = &'a CellBox>) -> Placing {
        Placing(Occupied::new(all))
    }

    /// Puts the piece in box `b` in place.
    pub(crate) fn add(&mut self, b: &CellBox) {
        self.0.add(b);
    }

    /// Whether the piece in box `b` can be put in place now.
    pub(crate) fn placeable(&self, b: &CellBox) -> bool {
        placeable(b, &self.0)
    }

    /// Whether a cell of box `b` is taken.
    pub(crate) fn taken(&self, b: &CellBox) -> bool {
        self.0.any_in(b)
    }

    /// The way the piece in box `b` goes in now, as [`route`] gives it
    /// (`far`: the inclusive corners of every piece that may come), or
    /// `None` if it cannot.
    pub(crate) fn route(&self, b: &CellBox, far: (Cell, Cell)) -> Option<Vec<CellBox>> {
        match self.0.bounds {
            Some((lo, hi)) => route(b, lo, hi, |x| self.0.any_in(x), far),
            // The first piece: from above, onto the table.
            None => route(b, b.min, b.max_excl().offset(-1, -1, -1), |_| false, far),
        }
    }
}

/// The placeability rule of the module docs.
fn placeable(b: &CellBox, occ: &Occupied) -> bool {
    let Some((lo, hi)) = occ.bounds else {
        return true;
    };
    matches!(
        escape(b, lo, hi, |x| occ.any_in(x), usize::MAX),
        Escape::Out
    )
}

/// What [`escape`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Escape {
    /// The piece travels out of the bounding box.
    Out,
    /// It cannot (or the search stopped at its limit); the inclusive
    /// corners of the positions it reached.
    Stuck(Cell, Cell),
}

/// Whether the piece in box `b` travels out of the bounding box `lo..=hi`
/// of the occupied cells (`taken` says whether a box meets one) by the
/// moves of the module docs: straight up or down, sideways one stud at a
/// time with its studs clear. A breadth-first search of its positions
/// that visits at most `limit` of them; from each, the straight ways out
/// (up, down, sideways) are tried first, as the search would find them
/// after a wide sweep of the free space around.
pub(crate) fn escape(
    b: &CellBox,
    lo: Cell,
    hi: Cell,
    taken: impl Fn(&CellBox) -> bool,
    limit: usize,
) -> Escape {
    match search_out(b, lo, hi, taken, limit, None) {
        Ok(_) => Escape::Out,
        Err((plo, phi)) => Escape::Stuck(plo, phi),
    }
}

/// How [`search_out`] found the piece leaving the bounding box, from the
/// last position of its way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Exit {
    /// The position is outside the bounding box already.
    Beyond,
    /// A straight move up, its column clear.
    Up,
    /// A straight press from below, its column clear.
    Down,
    /// A straight slide along `(dx, dy)`, its studs clear.
    Side(i32, i32),
}

/// The cells a piece in box `b` passes through on its way out of the
/// bounding box `lo..=hi` of the occupied cells (`taken` as for
/// [`escape`]), with one layer over and under each position (its studs'
/// clearance), and its last move carried on out of the bounding box
/// `far_lo..=far_hi` of every piece that may come (the finished build):
/// boxes that, free of other pieces, let it in by the same way however
/// many pieces are placed elsewhere. `None` if it cannot get out.
pub(crate) fn route(
    b: &CellBox,
    lo: Cell,
    hi: Cell,
    taken: impl Fn(&CellBox) -> bool,
    (far_lo, far_hi): (Cell, Cell),
) -> Option<Vec<CellBox>> {
    let mut parents = HashMap::new();
    let (at, exit) = search_out(b, lo, hi, taken, usize::MAX, Some(&mut parents)).ok()?;
    let grown = |p: Cell| CellBox {
        min: p.offset(0, 0, -1),
        sz: b.sz + 2,
        ..*b
    };
    let mut sweep = vec![grown(at)];
    let mut p = at;
    while let Some(&q) = parents.get(&p) {
        sweep.push(grown(q));
        p = q;
    }
    // The last move's direction, carried on past the far side.
    let (dx, dy, dz) = match exit {
        Exit::Up => (0, 0, 1),
        Exit::Down => (0, 0, -1),
        Exit::Side(dx, dy) => (dx, dy, 0),
        Exit::Beyond if at.z > hi.z => (0, 0, 1),
        Exit::Beyond if at.z + b.sz <= lo.z => (0, 0, -1),
        Exit::Beyond if at.x > hi.x => (1, 0, 0),
        Exit::Beyond if at.x + b.sx <= lo.x => (-1, 0, 0),
        Exit::Beyond if at.y > hi.y => (0, 1, 0),
        Exit::Beyond => (0, -1, 0),
    };
    // The cells of the positions from `a` on past the far side `flo..=fhi`
    // along one axis, for a piece `n` cells long there: `(start, length)`.
    let span = |a: i32, n: i32, d: i32, flo: i32, fhi: i32| match d {
        1 => (a, (fhi + 1 - a).max(0) + n),
        -1 => (a.min(flo - n), n + (a - (flo - n)).max(0)),
        _ => (a, n),
    };
    let (x0, sx) = span(at.x, b.sx, dx, far_lo.x, far_hi.x);
    let (y0, sy) = span(at.y, b.sy, dy, far_lo.y, far_hi.y);
    // A slide keeps its studs clear, a vertical move needs no more.
    let (z0, sz) = match dz {
        0 => (at.z - 1, b.sz + 2),
        _ => span(at.z, b.sz, dz, far_lo.z, far_hi.z),
    };
    sweep.push(CellBox {
        min: Cell::new(x0, y0, z0),
        sx,
        sy,
        sz,
    });
    Some(sweep)
}

/// Whether the piece in box `b`, moved to `p`, is wholly out of the
/// bounding box `lo..=hi`: its way out is found.
fn beyond(b: &CellBox, lo: Cell, hi: Cell, p: Cell) -> bool {
    p.x + b.sx <= lo.x
        || p.x > hi.x
        || p.y + b.sy <= lo.y
        || p.y > hi.y
        || p.z + b.sz <= lo.z
        || p.z > hi.z
}

/// Whether the straight way from `start` (a position and the key of its
/// direction) along `step` gets out: each position on the way answers
/// for itself (`ends`: out, blocked, or go on) unless its answer is kept
/// in `runs` already; every position walked keeps the answer, which is
/// theirs too.
fn along(
    runs: &mut crate::keyhash::KeyMap<(Cell, usize), bool>,
    (start, key): (Cell, usize),
    (dx, dy, dz): (i32, i32, i32),
    ends: impl Fn(Cell) -> Option<bool>,
) -> bool {
    let mut line = Vec::new();
    let mut q = start;
    let out = loop {
        if let Some(&known) = runs.get(&(q, key)) {
            break known;
        }
        line.push(q);
        if let Some(end) = ends(q) {
            break end;
        }
        q = q.offset(dx, dy, dz);
    };
    for q in line {
        runs.insert((q, key), out);
    }
    out
}

/// [`escape`]'s search: the last position of the way out and how it
/// leaves, or the inclusive corners of the positions reached. With
/// `parents`, each position the search reached is recorded with the one
/// it came from.
fn search_out(
    b: &CellBox,
    lo: Cell,
    hi: Cell,
    taken: impl Fn(&CellBox) -> bool,
    limit: usize,
    mut parents: Option<&mut HashMap<Cell, Cell>>,
) -> Result<(Cell, Exit), (Cell, Cell)> {
    let outside = |p: Cell| beyond(b, lo, hi, p);
    // Corners of the search region: the bounding box grown by the piece's
    // size + 1 on every side. Every path out meets a goal before leaving it.
    let (rmin, rmax) = (
        lo.offset(-b.sx - 1, -b.sy - 1, -b.sz - 1),
        hi.offset(1, 1, 1),
    );
    let in_region = |p: Cell| {
        (rmin.x..=rmax.x).contains(&p.x)
            && (rmin.y..=rmax.y).contains(&p.y)
            && (rmin.z..=rmax.z).contains(&p.z)
    };
    let free = |p: Cell| !taken(&moved(b, p));
    // The piece's footprint at `p`, layers `z0..z1`.
    let column = |p: Cell, z0: i32, z1: i32| CellBox {
        min: Cell::new(p.x, p.y, z0),
        sz: (z1 - z0).max(0),
        ..*b
    };
    // Stud clearance: nothing just above or just below the box.
    let clear = |p: Cell| {
        !taken(&column(p, p.z + b.sz, p.z + b.sz + 1)) && !taken(&column(p, p.z - 1, p.z))
    };
    if !free(b.min) {
        return Err((b.min, b.min));
    }
    let mut seen = crate::geom::CellSet::from_iter([b.min]);
    // Whether a piece at a position slides on straight out along one of
    // the four directions (by index), studs clear, from there; or goes
    // straight up ([`UP`]) or down ([`DOWN`]) out.
    const UP: usize = 4;
    const DOWN: usize = 5;
    let mut runs: crate::keyhash::KeyMap<(Cell, usize), bool> = Default::default();
    let mut queue = VecDeque::from([b.min]);
    let (mut plo, mut phi) = (b.min, b.min);
    while let Some(p) = queue.pop_front() {
        if outside(p) {
            return Ok((p, Exit::Beyond));
        }
        if seen.len() > limit {
            break;
        }
        plo = Cell::new(plo.x.min(p.x), plo.y.min(p.y), plo.z.min(p.z));
        phi = Cell::new(phi.x.max(p.x), phi.y.max(p.y), phi.z.max(p.z));
        // A straight drop from above or press from below: the column over
        // the piece clear to the top, or under it to the bottom (kept too,
        // for the positions over and under on the same column).
        for (key, dz) in [(UP, 1), (DOWN, -1)] {
            let out = along(&mut runs, (p, key), (0, 0, dz), |q| {
                let layer = if dz > 0 { q.z + b.sz } else { q.z - 1 };
                if layer > hi.z || layer < lo.z {
                    Some(true)
                } else {
                    taken(&column(q, layer, layer + 1)).then_some(false)
                }
            });
            if out {
                return Ok((p, if dz > 0 { Exit::Up } else { Exit::Down }));
            }
        }
        let clear_here = clear(p);
        // Straight sideways out, studs clear all the way. Whether the way
        // on from a position along a direction is clear is kept: the
        // positions of one line share it (a search of a wide hollow
        // otherwise walked every line again from each of its positions).
        if clear_here {
            for (d, (dx, dy)) in [(1, 0), (-1, 0), (0, 1), (0, -1)].into_iter().enumerate() {
                let first = p.offset(dx, dy, 0);
                let out = along(&mut runs, (first, d), (dx, dy, 0), |q| {
                    if !free(q) || !clear(q) {
                        Some(false)
                    } else {
                        outside(q).then_some(true)
                    }
                });
                if out {
                    return Ok((p, Exit::Side(dx, dy)));
                }
            }
        }
        let moves = [
            (0, 0, 1, false),
            (0, 0, -1, false),
            (1, 0, 0, true),
            (-1, 0, 0, true),
            (0, 1, 0, true),
            (0, -1, 0, true),
        ];
        for (dx, dy, dz, sideways) in moves {
            let q = p.offset(dx, dy, dz);
            if !in_region(q) || seen.contains(&q) || !free(q) {
                continue;
            }
            if sideways && !(clear_here && clear(q)) {
                continue;
            }
            seen.insert(q);
            if let Some(parents) = parents.as_deref_mut() {
                parents.insert(q, p);
            }
            queue.push_back(q);
        }
    }
    Err((plo, phi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::Rot;

    /// An assembly of bricks, one step each, from `(part, x, y, z, rot)`.
    fn build(pieces: &[(&str, i32, i32, i32, Rot)]) -> Assembly {
        let order: Vec<Placement> = pieces
            .iter()
            .map(|&(id, x, y, z, r)| {
                Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, y, z), r)
            })
            .collect();
        Assembly::from_order(&order, 24, Color::RED)
    }

    use Rot::{R0, R90};

    /// An assembly of any parts on layers `layer_ldu` high.
    fn build_in(layer_ldu: i32, pieces: &[(&str, i32, i32, i32, Rot)]) -> Assembly {
        let mut asm = build(pieces);
        asm.layer_ldu = layer_ldu;
        asm
    }

    fn not_connected(asm: &Assembly) -> Vec<usize> {
        verify(asm, None)
            .failures
            .iter()
            .filter_map(|f| match f {
                Failure::NotConnected { piece, .. } => Some(*piece),
                _ => None,
            })
            .collect()
    }

    /// A ring of 2 x 2 bricks on the ground round a 2 x 2 hole, closed by a
    /// lid of two courses of 2 x 6 bricks; `inner` is a 2 x 2 brick in the
    /// hole, put in before the lid or after it.
    fn closed_box(inner_first: bool) -> Assembly {
        let ring = [
            (0, 0),
            (2, 0),
            (4, 0),
            (0, 2),
            (4, 2),
            (0, 4),
            (2, 4),
            (4, 4),
        ];
        let mut pieces: Vec<(&str, i32, i32, i32, Rot)> =
            ring.iter().map(|&(x, y)| ("3003", x, y, 0, R0)).collect();
        let inner = ("3003", 2, 2, 0, R0);
        if inner_first {
            pieces.push(inner);
        }
        pieces.extend([0, 2, 4].map(|y| ("2456", 0, y, 1, R0)));
        // Across the lid, holding its rows together.
        pieces.extend([0, 2, 4].map(|x| ("2456", x, 0, 2, R90)));
        if !inner_first {
            pieces.push(inner);
        }
        build(&pieces)
    }

    /// The search's shortcuts (the straight ways out, each kept for the
    /// positions on its line) find a way out exactly where the moves
    /// alone do: a plain search of the moves on random clutter.
    #[test]
    fn the_way_out_is_found_exactly_where_the_moves_alone_find_one() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (lo, hi) = (Cell::new(0, 0, 0), Cell::new(7, 7, 5));
        let (mut outs, mut stuck) = (0, 0);
        for _ in 0..400 {
            let density = rng.gen_range(0.2..0.7);
            let mut cells = crate::geom::CellSet::default();
            let grid = CellBox {
                min: lo,
                sx: 8,
                sy: 8,
                sz: 6,
            };
            for c in grid.cells() {
                if rng.gen_bool(density) {
                    cells.insert(c);
                }
            }
            let b = CellBox {
                min: Cell::new(
                    rng.gen_range(0..7),
                    rng.gen_range(0..7),
                    rng.gen_range(0..6),
                ),
                sx: rng.gen_range(1..3),
                sy: rng.gen_range(1..3),
                sz: 1,
            };
            for c in b.cells() {
                cells.remove(&c);
            }
            let taken = |x: &CellBox| x.cells().any(|c| cells.contains(&c));
            let found = escape(&b, lo, hi, taken, usize::MAX) == Escape::Out;
            // The moves alone: up and down where the box is free, sideways
            // where its studs are clear here and there, until the box is
            // outside the bounds.
            let at = |p: Cell| CellBox { min: p, ..b };
            let clear = |p: Cell| {
                !taken(&CellBox {
                    min: p.offset(0, 0, 1),
                    ..b
                }) && !taken(&CellBox {
                    min: p.offset(0, 0, -1),
                    ..b
                })
            };
            let outside = |p: Cell| beyond(&b, lo, hi, p);
            let mut seen = crate::geom::CellSet::from_iter([b.min]);
            let mut queue = vec![b.min];
            let mut plain = false;
            while let Some(p) = queue.pop() {
                if outside(p) {
                    plain = true;
                    break;
                }
                for (dx, dy, dz) in [
                    (0, 0, 1),
                    (0, 0, -1),
                    (1, 0, 0),
                    (-1, 0, 0),
                    (0, 1, 0),
                    (0, -1, 0),
                ] {
                    let q = p.offset(dx, dy, dz);
                    let ok = !taken(&at(q)) && (dz != 0 || (clear(p) && clear(q)));
                    if ok && seen.insert(q) {
                        queue.push(q);
                    }
                }
            }
            assert_eq!(found, plain, "{b:?}");
            if found {
                outs += 1;
            } else {
                stuck += 1;
            }
        }
        assert!(outs > 50 && stuck > 50, "{outs} out, {stuck} stuck");
    }

    /// The way in of a brick hung under a beam is the column under it, on
    /// down past the build's lowest layer; a brick on top drops in from
    /// over the build's highest; a brick on the table between walls slides
    /// out of the end left open, its studs clear.
    #[test]
    fn a_route_goes_on_past_the_bounds_of_what_may_come() {
        // Every piece of `asm` put in place.
        let placed = |asm: &Assembly| {
            let boxes: Vec<CellBox> = asm
                .pieces
                .iter()
                .map(|p| p.placement.body(asm.layer_ldu).bbox)
                .collect();
            let mut placing = Placing::new(&boxes);
            for b in &boxes {
                placing.add(b);
            }
            placing
        };
        let placing = placed(&build(&[
            ("3003", 0, 0, 0, R0),
            ("3003", 0, 0, 1, R0),
            ("3001", 0, 0, 2, R0),
        ]));
        let far = (Cell::new(-5, -5, 0), Cell::new(9, 9, 6));
        let hung = CellBox {
            min: Cell::new(2, 0, 1),
            sx: 2,
            sy: 2,
            sz: 1,
        };
        let way = placing.route(&hung, far).expect("pressed up from below");
        assert_eq!(
            way.last(),
            Some(&CellBox {
                min: Cell::new(2, 0, -1),
                sz: 3,
                ..hung
            })
        );
        let top = CellBox {
            min: Cell::new(0, 0, 3),
            ..hung
        };
        let way = placing.route(&top, far).expect("dropped from above");
        assert_eq!(
            way.last(),
            Some(&CellBox {
                min: Cell::new(0, 0, 3),
                sz: 5,
                ..hung
            })
        );
        // A 2 x 2 between two walls three courses high on a floor, a course
        // clear of the floor and of a brick over it: it slides out along
        // y, the layers over it and under it clear.
        let placing = placed(&build(&[
            ("2456", 0, 0, 0, R0),
            ("2456", 0, 2, 0, R0),
            ("3001", 0, 0, 1, R90),
            ("3001", 0, 0, 2, R90),
            ("3001", 0, 0, 3, R90),
            ("3001", 4, 0, 1, R90),
            ("3001", 4, 0, 2, R90),
            ("3001", 4, 0, 3, R90),
            ("3003", 2, 0, 4, R0),
        ]));
        let inside = CellBox {
            min: Cell::new(2, 0, 2),
            ..hung
        };
        let way = placing.route(&inside, far).expect("slid out");
        let last = *way.last().unwrap();
        assert_eq!((last.min.x, last.sx, last.min.z, last.sz), (2, 2, 1, 3));
        assert!(
            last.min.y + last.sy > far.1.y + 2 || last.min.y < far.0.y - 1,
            "{last:?}"
        );
    }

    #[test]
    fn a_piece_inside_a_closed_cavity_is_refused() {
        // The lid first: the piece in the hole is shut in (the table under
        // it is no way in, though nothing stands between it and the ground).
        let late = verify(&closed_box(false), None);
        assert_eq!(
            late.failures,
            vec![Failure::Enclosed {
                piece: 14,
                step: Step(15)
            }],
            "{late}"
        );
        assert!(
            late.to_string().contains("inside a closed cavity"),
            "{late}"
        );
        // The same piece before the lid: built while the box is open.
        let early = verify(&closed_box(true), None);
        assert!(early.is_ok(), "{early}");
    }

    #[test]
    fn the_last_piece_closing_a_cavity_goes_in_from_outside() {
        // A lid piece goes into the last gap from above; a piece under an
        // overhang comes in from the side.
        let asm = build(&[
            ("3003", 0, 0, 0, R0),
            ("3003", 4, 0, 0, R0),
            ("2456", 0, 0, 1, R0),
            ("3003", 2, 0, 0, R0),
        ]);
        assert!(verify(&asm, None).is_ok());
    }

    #[test]
    fn slopes_take_studs_on_their_back_row_only() {
        // A 2x2 slope on a 2x4 (half-brick layers: a brick is two), its
        // back row at y = 1.
        let base = ("3001", 0, 0, 0, R0);
        let slope = ("3039", 0, 0, 2, R0);
        // A 1x2 across the back row holds; one on the front row does not,
        // since the front row has no studs (and its face must stay clear).
        let on_back = build_in(12, &[base, slope, ("3004", 0, 1, 4, R0)]);
        assert!(verify(&on_back, None).is_ok(), "{}", verify(&on_back, None));
        let on_front = build_in(12, &[base, slope, ("3004", 0, 0, 3, R0)]);
        let report = verify(&on_front, None);
        assert!(!report.is_ok());
        // The 1x2 on the front row sits on the slope's lower layer: it
        // overlaps the sloping face's cell.
        assert!(report
            .failures
            .iter()
            .any(|f| matches!(f, Failure::Overlap { .. })));
        // An inverted slope connects below only under its back row: a
        // 1x2 under its front row is not held.
        let inv = ("3660a", 0, 0, 4, R0);
        let under_back = build_in(12, &[base, ("3003", 0, 0, 2, R0), inv]);
        assert!(verify(&under_back, None).is_ok());
        let front_only = build_in(
            12,
            &[
                ("3004", 0, 0, 0, R0),
                ("3004", 0, 0, 2, R0),
                ("3660a", 0, 0, 4, R0),
            ],
        );
        assert_eq!(not_connected(&front_only), vec![2]);
    }

    #[test]
    fn plates_connect_on_plate_layers() {
        // A 2x4 brick is three plate layers; a plate on it, a brick on the
        // plate.
        let asm = build_in(
            8,
            &[
                ("3001", 0, 0, 0, R0),
                ("3020", 2, 0, 3, R0),
                ("3001", 4, 0, 4, R0),
            ],
        );
        assert!(verify(&asm, None).is_ok(), "{}", verify(&asm, None));
        // A plate floating one layer above is connected to nothing.
        let gap = build_in(8, &[("3001", 0, 0, 0, R0), ("3020", 0, 0, 4, R0)]);
        assert_eq!(not_connected(&gap), vec![1]);
    }

    #[test]
    fn staggered_two_layer_wall_in_a_valid_order_passes_with_its_cover() {
        // Layer 0: 1x4 at x 0..3 and 4..7; layer 1: 1x2, 1x4 across the
        // joint, 1x2. The second bottom brick goes in after the bridge, so it
        // is pressed up from below.
        let asm = build(&[
            ("3010", 0, 0, 0, R0),
            ("3010", 2, 0, 1, R0),
            ("3010", 4, 0, 0, R0),
            ("3004", 0, 0, 1, R0),
            ("3004", 6, 0, 1, R0),
        ]);
        let mut target = VoxelGrid::new(8, 1, 2);
        target.set_box(
            &CellBox {
                min: Cell::new(0, 0, 0),
                sx: 8,
                sy: 1,
                sz: 2,
            },
            true,
        );
        let report = verify(&asm, Some(&target));
        assert!(report.is_ok(), "{report}");
        assert_eq!(report.to_string(), "assembly verified: no failures");
    }

    #[test]
    fn a_piece_before_the_one_it_rests_on_is_not_connected() {
        let asm = build(&[
            ("3010", 0, 0, 0, R0),
            ("3010", 0, 0, 2, R0),
            ("3010", 0, 0, 1, R0),
        ]);
        let report = verify(&asm, None);
        // Connected in the end (one component), but not at its turn (and
        // the piece between them cannot be slid in afterwards).
        assert!(
            report.failures.contains(&Failure::NotConnected {
                piece: 1,
                step: Step(2)
            }),
            "{report}"
        );
        assert!(!report
            .failures
            .iter()
            .any(|f| matches!(f, Failure::Disconnected { .. })));
    }

    #[test]
    fn a_second_part_may_start_on_the_ground() {
        // Two posts on the table, then the bridge that joins them.
        let asm = build(&[
            ("3010", 0, 0, 0, R0),
            ("3010", 4, 0, 0, R0),
            ("3010", 2, 0, 1, R0),
        ]);
        let report = verify(&asm, None);
        assert!(report.is_ok(), "{report}");
    }

    #[test]
    fn separate_pieces_are_disconnected() {
        let asm = build(&[("3005", 0, 0, 0, R0), ("3005", 1, 0, 0, R0)]);
        let report = verify(&asm, None);
        assert_eq!(report.failures, [Failure::Disconnected { components: 2 }]);
        assert_eq!(components(&asm), 2);
        assert!(
            report.to_string().contains("falls apart into 2"),
            "{report}"
        );
    }

    #[test]
    fn thousands_of_pieces_on_one_spot_give_a_bounded_report() {
        // 30,000 2x4s at the same place: every one after the first overlaps
        // all earlier ones. Each is named with at most 8 of them, and the
        // display shows the first few and counts the rest.
        let pieces = vec![("3001", 0, 0, 0, R0); 30_000];
        let report = verify(&build(&pieces), None);
        let overlaps = report
            .failures
            .iter()
            .filter(|f| matches!(f, Failure::Overlap { .. }))
            .count();
        assert_eq!(overlaps, 28 + 8 * (30_000 - 8));
        assert!(report
            .failures
            .iter()
            .all(|f| matches!(f, Failure::Overlap { .. } | Failure::Disconnected { .. })));
        let text = report.to_string();
        assert_eq!(text.lines().count(), 1 + SHOWN_FAILURES + 1, "{text}");
        assert!(text.ends_with(&format!(
            "... and {} more",
            report.failures.len() - SHOWN_FAILURES
        )));
    }

    #[test]
    fn stacked_pairs_are_the_face_to_face_pairs_sorted() {
        // A 2x4 on two 2x2s side by side, and a 1x1 beside the stack.
        let asm = build(&[
            ("3003", 0, 0, 0, R0),
            ("3003", 2, 0, 0, R0),
            ("3005", 6, 0, 0, R0),
            ("3001", 0, 0, 1, R0),
            ("3005", 3, 1, 2, R0),
        ]);
        let bodies: Vec<Body> = asm.pieces.iter().map(|p| p.placement.body(24)).collect();
        assert_eq!(stacked_pairs(&bodies), [(0, 3), (1, 3), (3, 4)]);
    }

    #[test]
    fn overlap_names_both_pieces_and_a_cell() {
        // A 2x4 along x and one along y, crossing at (0..1, 0..1).
        let asm = build(&[
            ("3001", 0, 0, 0, R0),
            ("3005", 5, 5, 1, R0),
            ("3001", 0, 0, 0, R90),
        ]);
        let report = verify(&asm, None);
        assert_eq!(
            report.failures[0],
            Failure::Overlap {
                a: 0,
                b: 2,
                cell: Cell::new(0, 0, 0)
            }
        );
        // The overlapping piece is not also called unplaceable.
        assert!(!report
            .failures
            .iter()
            .any(|f| matches!(f, Failure::NotPlaceable { .. })));
    }

    #[test]
    fn cover_mismatch_counts_missing_and_extra_cells() {
        let asm = build(&[("3004", 0, 0, 0, R0)]); // cells (0,0,0), (1,0,0)
        let mut target = VoxelGrid::new(3, 1, 1);
        target.set(Cell::new(1, 0, 0), true);
        target.set(Cell::new(2, 0, 0), true);
        let report = verify(&asm, Some(&target));
        assert_eq!(
            report.failures,
            [Failure::CoverMismatch {
                missing: 1,
                extra: 1,
                first: Cell::new(0, 0, 0)
            }]
        );
    }

    #[test]
    fn piece_pressed_from_below_under_an_overhang_is_placeable() {
        // A 2x2 column two bricks high carries a 2x4 sticking out along +x;
        // a 2x2 then goes under the overhang at layer 1: the roof is above
        // it, but nothing is below it, so it is pressed up from below.
        let asm = build(&[
            ("3003", 0, 0, 0, R0),
            ("3003", 0, 0, 1, R0),
            ("3001", 0, 0, 2, R0),
            ("3003", 2, 0, 1, R0),
        ]);
        let report = verify(&asm, None);
        assert!(report.is_ok(), "{report}");
    }

    #[test]
    fn piece_sandwiched_between_floor_and_roof_is_not_placeable() {
        // Floor 1x4, a 1x1 pillar, a 1x4 roof; then a 1x2 in the one-layer
        // gap: its studs cannot slide under the roof.
        let asm = build(&[
            ("3010", 0, 0, 0, R0),
            ("3005", 0, 0, 1, R0),
            ("3010", 0, 0, 2, R0),
            ("3004", 2, 0, 1, R0),
        ]);
        let report = verify(&asm, None);
        assert_eq!(
            report.failures,
            [Failure::NotPlaceable {
                piece: 3,
                step: Step(4)
            }]
        );
    }

    /// A 6x6 box: floor at layer 0, walls at layers 1-3, roof at layer 4,
    /// leaving a 4x4x3 hollow; the wall on the x = 5 side is left out when
    /// `open`. Built in an order where every piece is connected and
    /// placeable, followed by a 2x2 hanging under the roof's centre.
    fn hollow_box(open: bool) -> Assembly {
        let mut p = vec![
            ("2456", 0, 0, 0, R0),  // floor row y 0..1
            ("3009", 0, 0, 1, R0),  // wall y = 0
            ("3010", 0, 1, 1, R90), // wall x = 0, y 1..4
            ("2456", 0, 2, 0, R0),  // floor row y 2..3, pressed from below
            ("2456", 0, 4, 0, R0),  // floor row y 4..5
            ("3009", 0, 5, 1, R0),  // wall y = 5
        ];
        if !open {
            p.push(("3010", 5, 1, 1, R90)); // wall x = 5
        }
        for z in 2..=3 {
            p.push(("3009", 0, 0, z, R0));
            p.push(("3010", 0, 1, z, R90));
            p.push(("3009", 0, 5, z, R0));
            if !open {
                p.push(("3010", 5, 1, z, R90));
            }
        }
        for y in [0, 2, 4] {
            p.push(("2456", 0, y, 4, R0));
        }
        p.push(("3003", 2, 2, 3, R0));
        build(&p)
    }

    #[test]
    fn piece_inside_a_closed_box_is_not_placeable() {
        let asm = hollow_box(false);
        let last = asm.pieces.len() - 1;
        let report = verify(&asm, None);
        assert_eq!(
            report.failures,
            [Failure::NotPlaceable {
                piece: last,
                step: Step(last as u32 + 1)
            }]
        );
    }

    #[test]
    fn piece_slid_in_under_a_roof_then_pressed_up_is_placeable() {
        // Same box with the x = 5 wall missing: roof above and floor below
        // defeat the fast path; the search lowers the 2x2 to layer 2 (clear
        // above and below), slides it out along +x, and succeeds.
        let asm = hollow_box(true);
        let report = verify(&asm, None);
        assert!(report.is_ok(), "{report}");
    }

    #[test]
    fn five_thousand_piece_mat_verifies() {
        // A 2-layer mat of 2x4s in running bond, 50 x 50 bricks a layer,
        // built row by row so each piece touches an earlier one.
        let mut p = Vec::new();
        for j in 0..50 {
            for k in 0..50 {
                p.push(("3001", 4 * k, 2 * j, 0, R0));
                p.push(("3001", 4 * k + 2, 2 * j + 1, 1, R0));
            }
        }
        // (No timing assertion here: speed goals live in benches/.)
        let report = verify(&build(&p), None);
        assert!(report.is_ok(), "{report}");
    }

    #[test]
    fn empty_and_single_piece_assemblies_pass() {
        assert!(verify(&build(&[]), None).is_ok());
        assert!(verify(&build(&[("3001", 7, -3, 2, R90)]), None).is_ok());
    }
}
