//! Re-sequencing a verified build course by course, so that its steps read
//! like instructions.
//!
//! The search's trace is a valid build order, but it can move up and down
//! between brick courses (the layout's derivation takes a piece hanging
//! under an overhang right after the piece it hangs from, and
//! `--search backward`'s derivation adds pieces in the reverse of the order
//! its trace took them away, wherever a rule matched). A person builds
//! a course, then the next; instructions that jump between courses make
//! many tiny steps. [`by_course`] re-sequences the same pieces greedily:
//! at each turn it adds, among the pieces on the ground or stud-connected
//! to what is already built, the one on the lowest course (earliest in the
//! trace on a tie). So the bottom course is laid first, as on a table, and
//! separate parts (the legs of an animal) rise side by side until the
//! courses above join them. Every piece still joins an earlier one or the
//! ground by construction, but a piece hung under the course above can be
//! shut in by the courses laid under it first: [`by_course_placeable`]
//! then holds the same greedy order to the ways each piece went in at its
//! turn in the trace, which keeps every order rule of the verifier.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use super::verify::{connections, verify, Placing};
use super::{Assembly, Placed};
use crate::geom::{Body, Cell, CellBox};

/// [`by_course`], where that order keeps the verifier's order rules; else
/// the course-by-course order held to the ways the pieces went in at
/// their turns in `assembly`'s own order (a verified one), which keeps
/// every rule by construction (`held_order`): a piece hung under the
/// course above goes in from below, after the piece it hangs from, and
/// the courses laid under it first can shut it in; held to its way in,
/// the pieces in that way come after it. `None` only if `assembly`'s own
/// order breaks those rules (the caller keeps it as it is).
///
/// Mending the course order instead, by moving everything under a
/// shut-in piece after it, cascaded (at 64 studs the cow's three pieces
/// hung one under another became 22 shut in) and often gave up: the
/// search's trace was kept, and at 60 studs the engine's trace broke at
/// step 51 where the held order stands. Holding only the pieces found
/// shut in, a round at a time, kept more of the course order but stood
/// less often (the engine at 52 studs broke at step 60).
pub fn by_course_placeable(assembly: &Assembly) -> Option<Assembly> {
    let bodies = bodies(assembly);
    let joins = connections(&bodies);
    let plain = reordered(assembly, &course_order(assembly, &bodies, &joins));
    if verify(&plain, None).is_ok() {
        return Some(plain);
    }
    let boxes: Vec<CellBox> = bodies.iter().map(|b| b.bbox).collect();
    let held = reordered(assembly, &held_order(assembly, &boxes, &joins));
    verify(&held, None).is_ok().then_some(held)
}

/// For each piece of `boxes` (in a verified order), the later pieces in
/// the way it went in at its turn: cells it passed through to its place
/// ([`route`](super::verify::route)'s, carried on out of the finished
/// build's bounds, so that the way stays open whatever else is placed
/// first), and the free cells that joined it to the air around the build
/// ([`Air::opening`]: the verifier's rule against closed cavities).
fn ways_in(boxes: &[CellBox]) -> Vec<Vec<usize>> {
    let n = boxes.len();
    let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
    let Some(far) = bounds(boxes) else {
        return after;
    };
    // Which piece fills each cell of the finished build.
    let (o, hi) = far;
    let (nx, ny, nz) = (hi.x - o.x + 1, hi.y - o.y + 1, hi.z - o.z + 1);
    let index = |x: i32, y: i32, z: i32| (((z - o.z) * ny + (y - o.y)) * nx + (x - o.x)) as usize;
    let mut owner = vec![u32::MAX; (nx * ny * nz) as usize];
    for (i, b) in boxes.iter().enumerate() {
        for c in b.cells() {
            owner[index(c.x, c.y, c.z)] = i as u32;
        }
    }
    let mut seen = vec![usize::MAX; n];
    let mut placing = Placing::new(boxes);
    let mut air = Air::new(far);
    for (i, b) in boxes.iter().enumerate() {
        let mut ways = placing.route(b, far).unwrap_or_default();
        ways.extend(air.opening(b, |c| placing.taken(c)));
        for w in ways {
            let xs = w.min.x.max(o.x)..(w.min.x + w.sx).min(hi.x + 1);
            let ys = w.min.y.max(o.y)..(w.min.y + w.sy).min(hi.y + 1);
            for z in w.min.z.max(o.z)..(w.min.z + w.sz).min(hi.z + 1) {
                for y in ys.clone() {
                    for x in xs.clone() {
                        let j = owner[index(x, y, z)];
                        if j != u32::MAX && j as usize > i && seen[j as usize] != i {
                            seen[j as usize] = i;
                            after[i].push(j as usize);
                        }
                    }
                }
            }
        }
        placing.add(b);
    }
    after
}

/// The course-by-course order of [`course_order`] in which each piece
/// comes before the later pieces (in `assembly`'s own order) in its way
/// in ([`ways_in`]). The assembly's own order keeps every such precedence
/// and joins each piece but its first to an earlier one or the ground;
/// its first piece, if off the ground, comes first here too (the
/// verifier asks no join of it, and none of the first piece placed). So
/// the first piece of it not yet placed can always come next: the order
/// never stalls.
fn held_order(assembly: &Assembly, boxes: &[CellBox], joins: &[Vec<usize>]) -> Vec<usize> {
    let n = boxes.len();
    let ways = ways_in(boxes);
    let mut waits = vec![0usize; n];
    for &j in ways.iter().flatten() {
        waits[j] += 1;
    }
    let layer_ldu = assembly.layer_ldu;
    let course = |i: usize| (assembly.pieces[i].placement.origin.z * layer_ldu).div_euclid(24);
    let ground = boxes.iter().map(|b| b.min.z).min().unwrap_or(0);
    let mut placed = vec![false; n];
    let mut queued = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(i32, usize)>> = BinaryHeap::new();
    let mut order = Vec::with_capacity(n);
    let mut first = 0;
    for (i, b) in boxes.iter().enumerate() {
        if b.min.z == ground && waits[i] == 0 {
            queued[i] = true;
            heap.push(Reverse((course(i), i)));
        }
    }
    // The first piece, if off the ground, before all else (it waits for
    // no piece: none comes before it).
    let mut next = (n > 0 && boxes[0].min.z != ground).then_some(0);
    if next.is_some() {
        queued[0] = true;
    }
    while order.len() < n {
        let i = match next.take().or_else(|| heap.pop().map(|Reverse((_, i))| i)) {
            Some(i) => i,
            None => {
                // Only for an order that was not verified: its first piece
                // not yet placed.
                while placed[first] {
                    first += 1;
                }
                queued[first] = true;
                first
            }
        };
        placed[i] = true;
        order.push(i);
        let joined = |j: usize, placed: &[bool]| {
            boxes[j].min.z == ground || joins[j].iter().any(|&k| placed[k])
        };
        for &j in &ways[i] {
            waits[j] -= 1;
            if waits[j] == 0 && !queued[j] && joined(j, &placed) {
                queued[j] = true;
                heap.push(Reverse((course(j), j)));
            }
        }
        for &j in &joins[i] {
            if waits[j] == 0 && !queued[j] {
                queued[j] = true;
                heap.push(Reverse((course(j), j)));
            }
        }
    }
    order
}

/// The free cells around a piece, searched for a way from its box to the
/// space around the build (beside the finished build's bounds or over
/// them, never under the table): the verifier's rule that no piece is
/// built inside a closed cavity.
struct Air {
    /// The inclusive corners of the search: the build's bounds grown by a
    /// cell at the sides and over the top.
    lo: Cell,
    hi: Cell,
    /// The search that last reached each cell, and the cell it came from.
    mark: Vec<u32>,
    from: Vec<u32>,
    search: u32,
}

impl Air {
    fn new((lo, hi): (Cell, Cell)) -> Air {
        let (lo, hi) = (lo.offset(-1, -1, 0), hi.offset(1, 1, 1));
        let n = ((hi.x - lo.x + 1) * (hi.y - lo.y + 1) * (hi.z - lo.z + 1)) as usize;
        Air {
            lo,
            hi,
            mark: vec![0; n],
            from: vec![0; n],
            search: 0,
        }
    }

    fn index(&self, c: Cell) -> Option<usize> {
        let (lo, hi) = (self.lo, self.hi);
        let inside = (lo.x..=hi.x).contains(&c.x)
            && (lo.y..=hi.y).contains(&c.y)
            && (lo.z..=hi.z).contains(&c.z);
        inside.then(|| {
            let (nx, ny) = (hi.x - lo.x + 1, hi.y - lo.y + 1);
            (((c.z - lo.z) * ny + (c.y - lo.y)) * nx + (c.x - lo.x)) as usize
        })
    }

    fn cell(&self, i: usize) -> Cell {
        let (nx, ny) = (self.hi.x - self.lo.x + 1, self.hi.y - self.lo.y + 1);
        let i = i as i32;
        self.lo.offset(i % nx, (i / nx) % ny, i / (nx * ny))
    }

    /// Whether `c` is on the search's border: the space around the build.
    fn border(&self, c: Cell) -> bool {
        c.x == self.lo.x
            || c.y == self.lo.y
            || c.x == self.hi.x
            || c.y == self.hi.y
            || c.z == self.hi.z
    }

    /// Cells free now (`taken` says which are not) that join the box `b`
    /// face to face to the space around the build: the box's column
    /// straight up or a straight run of its slab sideways where one is
    /// free, else the shortest path a breadth-first search finds. Empty
    /// if there is none.
    fn opening(&mut self, b: &CellBox, taken: impl Fn(&CellBox) -> bool) -> Vec<CellBox> {
        let (lo, hi) = (self.lo, self.hi);
        let m = b.max_excl();
        let straight = [
            CellBox {
                min: Cell::new(b.min.x, b.min.y, m.z),
                sz: hi.z + 1 - m.z,
                ..*b
            },
            CellBox {
                min: Cell::new(m.x, b.min.y, b.min.z),
                sx: hi.x + 1 - m.x,
                ..*b
            },
            CellBox {
                min: Cell::new(lo.x, b.min.y, b.min.z),
                sx: b.min.x - lo.x,
                ..*b
            },
            CellBox {
                min: Cell::new(b.min.x, m.y, b.min.z),
                sy: hi.y + 1 - m.y,
                ..*b
            },
            CellBox {
                min: Cell::new(b.min.x, lo.y, b.min.z),
                sy: b.min.y - lo.y,
                ..*b
            },
        ];
        if let Some(w) = straight.into_iter().find(|w| w.volume() > 0 && !taken(w)) {
            return vec![w];
        }
        self.search += 1;
        let search = self.search;
        let mut queue = VecDeque::new();
        for c in b.cells() {
            if let Some(i) = self.index(c) {
                self.mark[i] = search;
                self.from[i] = u32::MAX;
                queue.push_back(i);
            }
        }
        while let Some(i) = queue.pop_front() {
            let c = self.cell(i);
            if self.border(c) {
                let mut path = Vec::new();
                let mut k = i;
                while self.from[k] != u32::MAX {
                    path.push(unit(self.cell(k)));
                    k = self.from[k] as usize;
                }
                return path;
            }
            for (dx, dy, dz) in crate::geom::FACES {
                let n = c.offset(dx, dy, dz);
                let Some(j) = self.index(n) else { continue };
                if self.mark[j] != search && !taken(&unit(n)) {
                    self.mark[j] = search;
                    self.from[j] = i as u32;
                    queue.push_back(j);
                }
            }
        }
        Vec::new()
    }
}

/// The box of the one cell `c`.
fn unit(c: Cell) -> CellBox {
    CellBox {
        min: c,
        sx: 1,
        sy: 1,
        sz: 1,
    }
}

/// The inclusive corners of the boxes, `None` if there are none.
fn bounds(boxes: &[CellBox]) -> Option<(Cell, Cell)> {
    let all = boxes.iter().copied().reduce(|a, b| a.union(&b))?;
    Some((all.min, all.max_excl().offset(-1, -1, -1)))
}

/// `assembly`'s pieces in `order` (indices into its pieces), one a step.
fn reordered(assembly: &Assembly, order: &[usize]) -> Assembly {
    Assembly {
        pieces: order
            .iter()
            .enumerate()
            .map(|(k, &i)| Placed {
                step: super::Step(k as u32 + 1),
                ..assembly.pieces[i]
            })
            .collect(),
        layer_ldu: assembly.layer_ldu,
    }
}

/// The assembly's pieces in course-by-course order, steps renumbered one
/// piece a step (regroup afterwards).
pub fn by_course(assembly: &Assembly) -> Assembly {
    let bodies = bodies(assembly);
    reordered(
        assembly,
        &course_order(assembly, &bodies, &connections(&bodies)),
    )
}

/// The pieces' bodies.
fn bodies(assembly: &Assembly) -> Vec<Body> {
    assembly
        .pieces
        .iter()
        .map(|p| p.placement.body(assembly.layer_ldu))
        .collect()
}

/// [`by_course`]'s order, as indices into `assembly`'s pieces, whose
/// `bodies` are stud-connected as `joins` says ([`connections`]).
fn course_order(assembly: &Assembly, bodies: &[Body], joins: &[Vec<usize>]) -> Vec<usize> {
    let n = assembly.pieces.len();
    let layer_ldu = assembly.layer_ldu;
    let course = |i: usize| (assembly.pieces[i].placement.origin.z * layer_ldu).div_euclid(24);
    let mut placed = vec![false; n];
    let mut queued = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(i32, usize)>> = BinaryHeap::new();
    let mut order: Vec<usize> = Vec::with_capacity(n);
    let mut next_seed = 0;
    // Everything on the ground can start at once: a person lays the bottom
    // course on the table before building on it.
    let ground = bodies.iter().map(|b| b.bbox.min.z).min().unwrap_or(0);
    for (i, b) in bodies.iter().enumerate() {
        if b.bbox.min.z == ground {
            queued[i] = true;
            heap.push(Reverse((course(i), i)));
        }
    }
    while order.len() < n {
        if heap.is_empty() {
            // A new start: the lowest, earliest piece not yet placed (the
            // first time; more only if the build had several components).
            let start = (next_seed..n)
                .filter(|&i| !placed[i])
                .min_by_key(|&i| (course(i), i))
                .expect("unplaced pieces remain");
            next_seed = start.min(next_seed);
            queued[start] = true;
            heap.push(Reverse((course(start), start)));
        }
        let Reverse((_, i)) = heap.pop().expect("not empty");
        placed[i] = true;
        order.push(i);
        for &j in &joins[i] {
            if !queued[j] {
                queued[j] = true;
                heap.push(Reverse((course(j), j)));
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    /// A 2 x 2 brick on the table in a walled pen under a lid, beside a
    /// free 2 x 2 of the pen whose wall has a gap: no straight run of free
    /// cells leaves the brick, and the way the air reaches it bends
    /// through the free part and out of the gap.
    #[test]
    fn the_air_reaches_a_brick_in_a_pen_through_its_gap() {
        let cell = |x, y, z, sx, sy| CellBox {
            min: Cell::new(x, y, z),
            sx,
            sy,
            sz: 1,
        };
        let mut taken = vec![cell(0, 0, 1, 8, 6)];
        for (x, y) in [
            (0, 0),
            (2, 0),
            (4, 0),
            (6, 0),
            (0, 2),
            (6, 2),
            (0, 4),
            (2, 4),
            (6, 4),
        ] {
            taken.push(cell(x, y, 0, 2, 2));
        }
        let far = (Cell::new(0, 0, 0), Cell::new(7, 5, 1));
        let brick = cell(2, 2, 0, 2, 2);
        let meets = |taken: &[CellBox], b: &CellBox| taken.iter().any(|t| t.intersects(b));
        let way = Air::new(far).opening(&brick, |b| meets(&taken, b));
        assert!(way.iter().all(|c| c.volume() == 1 && !meets(&taken, c)));
        // Out through the gap, the free part of the pen on the way.
        let cells: Vec<Cell> = way.iter().map(|c| c.min).collect();
        assert!(cells
            .iter()
            .any(|c| c.x >= 4 && c.y >= 4 && c.x < 6 && c.y < 6));
        assert!(cells
            .iter()
            .any(|c| c.x >= 4 && c.x < 6 && (2..4).contains(&c.y)));
        assert!(cells
            .iter()
            .any(|c| c.y == 6 || c.y == -1 || c.x == -1 || c.x == 8));
        // The gap closed, the pen has no way out but under the table.
        taken.push(cell(4, 4, 0, 2, 2));
        assert!(Air::new(far)
            .opening(&brick, |b| meets(&taken, b))
            .is_empty());
    }

    #[test]
    fn a_zigzag_trace_is_built_course_by_course() {
        let brick = PartKind::from_id("3001").unwrap();
        // A 3-course wall in running bond, traced a column at a time.
        let mut order = Vec::new();
        for i in 0..4 {
            order.push(Placement::new(brick, Cell::new(4 * i, 0, 0), Rot::R0));
            order.push(Placement::new(brick, Cell::new(4 * i + 2, 0, 1), Rot::R0));
            order.push(Placement::new(brick, Cell::new(4 * i, 0, 2), Rot::R0));
        }
        let a = Assembly::from_order(&order, 24, Color::RED);
        assert!(verify(&a, None).is_ok());
        let b = by_course(&a);
        assert!(verify(&b, None).is_ok(), "{}", verify(&b, None));
        let courses: Vec<i32> = b.pieces.iter().map(|p| p.placement.origin.z).collect();
        // The bottom course is laid on the table first, then each course
        // in one run.
        assert_eq!(courses, [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]);
        let mut sorted = b.pieces.iter().map(|p| p.placement).collect::<Vec<_>>();
        sorted.sort_by_key(|p| (p.origin.z, p.origin.x));
        let mut orig = order.clone();
        orig.sort_by_key(|p| (p.origin.z, p.origin.x));
        assert_eq!(sorted, orig, "the same pieces");
    }
}
