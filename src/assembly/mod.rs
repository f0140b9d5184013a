//! The assembly: the ordered, verified list of placements every exporter reads.
//!
//! An [`Assembly`] is the single plan that the LDraw, glTF, parts-list and
//! booklet back ends trust. It is produced by the search and checked by the
//! independent [`verify`] module before anything is written.

pub mod metrics;
pub mod order;
pub mod stairs;
pub mod verify;

use serde::Serialize;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::catalog::{Color, Palette, PartKind, LAYER_PALETTE, RANDOM_PALETTE};
use crate::geom::{Body, Cell, Rot};
use crate::voxel::{VoxelColors, VoxelGrid};

/// A building step number, counted from 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Step(pub u32);

/// One piece placed in the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Placement {
    /// Which part.
    pub part: PartKind,
    /// Minimum corner of the cells the piece fills.
    pub origin: Cell,
    /// Rotation about the vertical axis.
    pub rot: Rot,
}

impl Placement {
    /// A placement with its rotation made canonical for the part's symmetry.
    pub fn new(part: PartKind, origin: Cell, rot: Rot) -> Self {
        Placement {
            part,
            origin,
            rot: part.spec().canonical_rot(rot),
        }
    }

    /// The cells the piece fills and where it connects, in a grid of
    /// `layer_ldu`-high layers.
    pub fn body(&self, layer_ldu: i32) -> Body {
        self.part.body(self.rot, self.origin, layer_ldu)
    }
}

/// A placement with its place in the build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Placed {
    /// Where and what.
    pub placement: Placement,
    /// The step that adds it.
    pub step: Step,
    /// Its colour.
    pub color: Color,
}

/// The ordered build: pieces in the order a person adds them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Assembly {
    /// Pieces in build order; steps never decrease.
    pub pieces: Vec<Placed>,
    /// Height of a voxel layer in LDU: 24 for bricks, 12 with slopes, 8
    /// with plates.
    pub layer_ldu: i32,
}

impl Assembly {
    /// An assembly from placements in build order, one step each.
    pub fn from_order(order: &[Placement], layer_ldu: i32, color: Color) -> Self {
        Assembly {
            pieces: order
                .iter()
                .enumerate()
                .map(|(i, &placement)| Placed {
                    placement,
                    step: Step(i as u32 + 1),
                    color,
                })
                .collect(),
            layer_ldu,
        }
    }

    /// Number of steps (the highest step number).
    pub fn step_count(&self) -> u32 {
        self.pieces.last().map_or(0, |p| p.step.0)
    }

    /// The build as it stands after step `step`: the pieces of steps
    /// `1..=step`.
    pub fn through_step(&self, step: u32) -> Assembly {
        Assembly {
            pieces: self
                .pieces
                .iter()
                .filter(|p| p.step.0 <= step)
                .cloned()
                .collect(),
            layer_ldu: self.layer_ldu,
        }
    }

    /// Regroups the steps. `Auto` (the default) makes a step of each run
    /// of pieces on one brick course, a big run split into balanced steps
    /// of at most [`STEP_PIECES`] pieces, more when that is needed to keep
    /// within [`MAX_STEPS`]; a run of fewer than [`STEP_MIN_PIECES`] (a
    /// piece that hangs from the course above comes after it, between two
    /// runs) joins the smaller of its neighbours on the next course when
    /// the two fit in one step, or else shares that neighbour's pieces in
    /// halves, and what is still small joins a neighbour across three
    /// courses (see `merge_runs`); `Each` one piece a step; `Size(n)` n pieces a
    /// step; `Layer` one step per course run.
    pub fn regroup(&mut self, grouping: StepGrouping) {
        let layer_ldu = self.layer_ldu;
        // Courses by brick height (24 LDU), whatever the grid's layer height.
        let course = |p: &Placed| (p.placement.origin.z * layer_ldu).div_euclid(24);
        let mut runs: Vec<usize> = Vec::new();
        let mut last = None;
        for p in &self.pieces {
            let c = course(p);
            match runs.last_mut() {
                Some(n) if last == Some(c) => *n += 1,
                _ => runs.push(1),
            }
            last = Some(c);
        }
        let sizes: Vec<usize> = match grouping {
            StepGrouping::Each => vec![1; self.pieces.len()],
            StepGrouping::Size(n) => {
                let n = n.max(1);
                let len = self.pieces.len();
                (0..len.div_ceil(n)).map(|i| n.min(len - i * n)).collect()
            }
            StepGrouping::Layer => runs,
            StepGrouping::Auto => {
                let courses: Vec<i32> = self.pieces.iter().map(course).collect();
                let split = |cap: usize| -> Vec<usize> {
                    runs.iter()
                        .flat_map(|&n| {
                            let k = n.div_ceil(cap);
                            // Balanced: sizes differ by at most one.
                            (0..k).map(move |i| n / k + usize::from(i < n % k))
                        })
                        .collect()
                };
                let mut cap = STEP_PIECES;
                let mut sizes = merge_runs(split(cap), cap, &courses);
                while sizes.len() > MAX_STEPS && cap < self.pieces.len() {
                    cap += 1;
                    sizes = merge_runs(split(cap), cap, &courses);
                }
                if sizes.len() > MAX_STEPS {
                    // More course runs than LeoCAD shows: merge runs.
                    let n = self.pieces.len().div_ceil(MAX_STEPS);
                    let len = self.pieces.len();
                    sizes = (0..len.div_ceil(n)).map(|i| n.min(len - i * n)).collect();
                }
                sizes
            }
        };
        let mut i = 0;
        for (step, &size) in sizes.iter().enumerate() {
            for p in &mut self.pieces[i..i + size] {
                p.step = Step(step as u32 + 1);
            }
            i += size;
        }
    }

    /// Colours every piece by `palette`; `seed` drives
    /// [`Palette::Random`], so the same seed gives the same colours. A
    /// piece always takes a colour its part is made in: random colours are
    /// drawn among those, and a single colour the part is not made in gives
    /// way to the nearest one it is.
    pub fn paint(&mut self, palette: Palette, seed: u64) {
        let layer_ldu = self.layer_ldu;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for p in &mut self.pieces {
            let part = p.placement.part;
            let want = match palette {
                Palette::Single(c) => c,
                Palette::Random => {
                    let made: Vec<Color> = RANDOM_PALETTE
                        .iter()
                        .copied()
                        .filter(|&c| part.exists_in(c))
                        .collect();
                    made[rng.gen_range(0..made.len())]
                }
                Palette::Layers | Palette::Mesh => {
                    // By brick course (24 LDU), whatever the layer height.
                    let course = (p.placement.origin.z * layer_ldu).div_euclid(24);
                    LAYER_PALETTE[course.rem_euclid(LAYER_PALETTE.len() as i32) as usize]
                }
            };
            p.color = part.nearest_color(want, None);
        }
    }

    /// Colours every piece from the voxel colours `colors` (cells indexed
    /// as in `grid`): the colour most of the surface voxels it covers show,
    /// else most of its voxels, else that of the nearest coloured voxel
    /// (a piece filling only cells outside the model); or, where its part
    /// is not made in that colour, the nearest one it is made in (among
    /// the model's colours when `--colors` limited them).
    pub fn paint_voxels(&mut self, grid: &VoxelGrid, colors: &VoxelColors) {
        let layer_ldu = self.layer_ldu;
        let limit: Option<Vec<Color>> = colors
            .limited
            .then(|| colors.used.iter().map(|&(c, _)| c).collect());
        for p in &mut self.pieces {
            let body = p.placement.body(layer_ldu);
            let cells: Vec<Cell> = body.cells().filter(|&c| grid.in_bounds(c)).collect();
            let vote = |surface_only: bool| {
                let mut n: std::collections::BTreeMap<Color, usize> = Default::default();
                for &c in &cells {
                    let i = grid.index(c);
                    if let Some(col) =
                        colors.cells[i].filter(|_| !surface_only || colors.surface[i])
                    {
                        *n.entry(col).or_default() += 1;
                    }
                }
                n.into_iter()
                    .max_by_key(|&(c, k)| (k, std::cmp::Reverse(c)))
                    .map(|(c, _)| c)
            };
            let near = || {
                (1..=4).find_map(|r| {
                    body.cells().find_map(|c| {
                        (-r..=r).find_map(|dz| {
                            (-r..=r).find_map(|dy| {
                                (-r..=r).find_map(|dx| {
                                    let n = c.offset(dx, dy, dz);
                                    grid.in_bounds(n)
                                        .then(|| colors.cells[grid.index(n)])
                                        .flatten()
                                })
                            })
                        })
                    })
                })
            };
            if let Some(c) = vote(true).or_else(|| vote(false)).or_else(near) {
                p.color = p.placement.part.nearest_color(c, limit.as_deref());
            }
        }
    }

    /// Pieces counted by part, in catalog order.
    pub fn counts_by_part(&self) -> Vec<(PartKind, usize)> {
        let mut counts = std::collections::BTreeMap::new();
        for p in &self.pieces {
            *counts.entry(p.placement.part).or_insert(0) += 1;
        }
        counts.into_iter().collect()
    }
}

/// New pieces a step holds at most by default, so a person sees at once
/// what to add (a course with more is split into several steps).
pub const STEP_PIECES: usize = 8;

/// New pieces a step holds at least where the model allows: smaller runs
/// join a neighbouring step (see [`Assembly::regroup`]).
pub const STEP_MIN_PIECES: usize = 3;

/// Joins the groups of fewer than [`STEP_MIN_PIECES`] to a neighbour
/// (see [`merge_small`]) on at most two neighbouring courses, then those
/// that could join none on at most three: a model that goes back and
/// forth between courses (pieces hanging from the course above, between
/// runs of the courses below and above) is not left in steps of one or
/// two pieces.
fn merge_runs(sizes: Vec<usize>, cap: usize, courses: &[i32]) -> Vec<usize> {
    let sizes = merge_small(sizes, cap, courses, 1);
    merge_small(sizes, cap, courses, 2)
}

/// Joins each group of fewer than [`STEP_MIN_PIECES`] to the smaller of
/// its neighbours (the one before on a tie) when the two hold at most
/// `cap` pieces whose courses are at most `reach` apart (`courses[i]` is
/// piece `i`'s); when they hold more than `cap`, the two share their
/// pieces in halves instead (a piece hanging under a full step of the
/// course above: 8 + 1 becomes 5 + 4). Until no group changes; the order
/// of pieces is unchanged.
fn merge_small(mut sizes: Vec<usize>, cap: usize, courses: &[i32], reach: i32) -> Vec<usize> {
    // Each group's lowest and highest course.
    let mut span: Vec<(i32, i32)> = Vec::with_capacity(sizes.len());
    let mut at = 0;
    for &n in &sizes {
        span.push(course_span(&courses[at..at + n]));
        at += n;
    }
    let joined = |a: (i32, i32), b: (i32, i32)| (a.0.min(b.0), a.1.max(b.1));
    let near = |a: (i32, i32), b: (i32, i32)| {
        let (lo, hi) = joined(a, b);
        hi - lo <= reach
    };
    let fits = |a: (i32, i32), b: (i32, i32), n: usize| n <= cap && near(a, b);
    let span_of = |start: usize, n: usize| course_span(&courses[start..start + n]);
    // Each pass goes along the groups once: those behind it in `done`,
    // those ahead in `ahead` (the current one last), so that joining two
    // never moves the rest.
    loop {
        let mut changed = false;
        let mut done: Vec<(usize, (i32, i32))> = Vec::with_capacity(sizes.len());
        let mut ahead: Vec<(usize, (i32, i32))> = sizes
            .iter()
            .copied()
            .zip(span.iter().copied())
            .rev()
            .collect();
        // Pieces in the groups behind.
        let mut start = 0;
        while let Some(&(n, sp)) = ahead.last() {
            if n >= STEP_MIN_PIECES {
                done.push((n, sp));
                ahead.pop();
                start += n;
                continue;
            }
            let next = ahead.len().checked_sub(2).map(|k| ahead[k]);
            let before = done
                .last()
                .map(|&(m, s)| (m + n, s))
                .filter(|&(m, s)| fits(s, sp, m));
            let after = next
                .map(|(m, s)| (m + n, s))
                .filter(|&(m, s)| fits(s, sp, m));
            match (before, after) {
                (Some((b, s)), a) if a.is_none_or(|a| b <= a.0) => {
                    *done.last_mut().expect("a group behind") = (b, joined(s, sp));
                    ahead.pop();
                    start += n;
                    changed = true;
                }
                (_, Some((a, s))) => {
                    ahead.pop();
                    *ahead.last_mut().expect("a group ahead") = (a, joined(sp, s));
                    changed = true;
                }
                _ => {
                    // Too many for one step: the group takes pieces from
                    // the smaller neighbour it may share a step with,
                    // the two halves of their pieces.
                    let before = done
                        .last()
                        .map(|&(m, s)| (m, s))
                        .filter(|&(m, s)| m + n >= 2 * STEP_MIN_PIECES && near(s, sp));
                    let after = next.filter(|&(m, s)| m + n >= 2 * STEP_MIN_PIECES && near(s, sp));
                    match (before, after) {
                        (Some((m, _)), a) if a.is_none_or(|a| m <= a.0) => {
                            // The earlier group keeps the larger half.
                            let total = m + n;
                            let first = start - m;
                            let (na, nb) = (total - total / 2, total / 2);
                            *done.last_mut().expect("a group behind") = (na, span_of(first, na));
                            *ahead.last_mut().expect("the group") = (nb, span_of(first + na, nb));
                            start = first + na;
                        }
                        (_, Some((m, _))) => {
                            let total = m + n;
                            let (na, nb) = (total - total / 2, total / 2);
                            let k = ahead.len();
                            ahead[k - 1] = (na, span_of(start, na));
                            ahead[k - 2] = (nb, span_of(start + na, nb));
                        }
                        _ => {
                            done.push((n, sp));
                            ahead.pop();
                            start += n;
                            continue;
                        }
                    }
                    changed = true;
                }
            }
        }
        (sizes, span) = done.into_iter().unzip();
        if !changed {
            return sizes;
        }
    }
}

/// The lowest and highest of `courses`.
fn course_span(courses: &[i32]) -> (i32, i32) {
    (
        courses.iter().copied().min().unwrap_or(0),
        courses.iter().copied().max().unwrap_or(0),
    )
}

/// Steps LeoCAD shows at most (its step counter is one byte); a model with
/// more steps loads, but its later steps are missing from the view.
pub const MAX_STEPS: usize = 255;

/// How pieces are grouped into steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StepGrouping {
    /// A step per run of pieces on one course, split into balanced steps
    /// of at most [`STEP_PIECES`] pieces, more a step when that keeps the
    /// build within [`MAX_STEPS`] (the default).
    Auto,
    /// One piece a step.
    Each,
    /// At most this many pieces a step.
    Size(usize),
    /// A new step whenever the build moves to another layer.
    Layer,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assembly(n: usize) -> Assembly {
        let part = PartKind::from_id("3005").unwrap();
        let order: Vec<Placement> = (0..n)
            .map(|i| Placement::new(part, Cell::new(0, 0, i as i32 / 3), Rot::R0))
            .collect();
        Assembly::from_order(&order, 24, Color::RED)
    }

    #[test]
    fn auto_steps_stay_within_what_leocad_shows() {
        // Three pieces a course: a step a course, the last course's two
        // pieces joining the step before.
        let mut small = assembly(200);
        small.regroup(StepGrouping::Auto);
        assert_eq!(small.step_count(), 66);
        // 1000 courses would be 334 steps: runs are merged to stay in 255.
        let mut big = assembly(1000);
        big.regroup(StepGrouping::Auto);
        assert_eq!(big.step_count(), 250);
        assert!(big.step_count() as usize <= MAX_STEPS);
        let mut sized = assembly(10);
        sized.regroup(StepGrouping::Size(4));
        assert_eq!(sized.step_count(), 3);
        let mut layers = assembly(9);
        layers.regroup(StepGrouping::Layer);
        assert_eq!(layers.step_count(), 3);
        let mut each = assembly(9);
        each.regroup(StepGrouping::Each);
        assert_eq!(each.step_count(), 9);
    }

    #[test]
    fn small_runs_join_a_neighbouring_step() {
        // Piece courses of groups of the given sizes and courses.
        let courses = |groups: &[(usize, i32)]| -> (Vec<usize>, Vec<i32>) {
            let sizes = groups.iter().map(|g| g.0).collect();
            let c = groups.iter().flat_map(|&(n, c)| vec![c; n]).collect();
            (sizes, c)
        };
        let m = |groups: &[(usize, i32)]| {
            let (sizes, c) = courses(groups);
            merge_small(sizes, 8, &c, 1)
        };
        assert_eq!(m(&[(5, 0), (1, 1), (1, 0), (6, 1)]), vec![7, 6]);
        assert_eq!(m(&[(1, 0), (1, 1), (1, 0), (1, 1)]), vec![4]);
        // Too many for one step: the small group takes half of its
        // neighbour's pieces (the one before on a tie).
        assert_eq!(m(&[(8, 0), (1, 1), (8, 2)]), vec![5, 4, 8]);
        assert_eq!(m(&[(8, 3), (1, 1), (8, 1)]), vec![8, 5, 4]);
        assert_eq!(m(&[(2, 0), (7, 1)]), vec![5, 4]);
        // Never across courses further apart.
        assert_eq!(m(&[(1, 0), (8, 2)]), vec![1, 8]);
        // Then what is still small joins across three courses.
        assert_eq!(m(&[(4, 2), (2, 0), (4, 2)]), vec![4, 2, 4]);
        let (sizes, c) = courses(&[(4, 2), (2, 0), (4, 2)]);
        assert_eq!(merge_runs(sizes, 8, &c), vec![6, 4]);
        assert_eq!(m(&[(4, 0), (2, 1), (3, 2)]), vec![4, 5]);
        // A step spans at most two neighbouring courses.
        assert_eq!(m(&[(4, 0), (1, 2), (3, 4)]), vec![4, 1, 3]);
        assert_eq!(m(&[(1, 0), (1, 1), (1, 2)]), vec![2, 1]);
        assert!(m(&[]).is_empty());
    }

    #[test]
    fn a_big_course_is_split_into_balanced_steps() {
        let part = PartKind::from_id("3005").unwrap();
        let order: Vec<Placement> = (0..20)
            .map(|i| Placement::new(part, Cell::new(i, 0, 0), Rot::R0))
            .chain((0..3).map(|i| Placement::new(part, Cell::new(i, 0, 1), Rot::R0)))
            .collect();
        let mut a = Assembly::from_order(&order, 24, Color::RED);
        a.regroup(StepGrouping::Auto);
        let mut sizes = vec![0; a.step_count() as usize];
        for p in &a.pieces {
            sizes[p.step.0 as usize - 1] += 1;
        }
        assert_eq!(sizes, [7, 7, 6, 3]);
        // Steps never mix courses.
        for w in a.pieces.windows(2) {
            if w[0].placement.origin.z != w[1].placement.origin.z {
                assert_ne!(w[0].step, w[1].step);
            }
        }
    }

    #[test]
    fn palettes_paint_by_layer_at_random_or_all_alike() {
        let mut a = assembly(9);
        a.paint(Palette::Layers, 1);
        let colors: Vec<u16> = a.pieces.iter().map(|p| p.color.0).collect();
        assert_eq!(colors, [4, 4, 4, 15, 15, 15, 4, 4, 4]);
        a.paint(Palette::Single(Color(1)), 1);
        assert!(a.pieces.iter().all(|p| p.color == Color(1)));
        let mut b = assembly(200);
        b.paint(Palette::Random, 7);
        let mut c = b.clone();
        c.paint(Palette::Random, 7);
        assert_eq!(b, c);
        let distinct: std::collections::BTreeSet<_> = b.pieces.iter().map(|p| p.color).collect();
        assert_eq!(distinct.len(), RANDOM_PALETTE.len());
        c.paint(Palette::Random, 8);
        assert_ne!(b, c);
    }
}
