//! Local repair: joining the bodies a layout left apart.
//!
//! Laying course by course, a piece that rests on nothing (the first piece
//! of an overhang, a handle's lowest step) starts a body of its own, and the
//! courses above usually join it to the rest. Where they do not, instead of
//! backtracking, [`Layout::join`] repairs locally: a piece of the loose body
//! grows into a bigger piece that reaches a piece of another body above or
//! below it (filling empty cells beside it), or a new piece is laid on top
//! of it or under it, across to another body, or it and a piece beside it
//! are laid again with a piece across the two. Each repair takes the fewest
//! cells outside the model. Last, a body that meets the rest only at a
//! corner (a thin fin's far columns, each touching the one before along an
//! edge) has the two pieces there laid again with one across the corner,
//! over cells the surface passes through. A body nothing can join is left
//! out, and the report says where.

use super::layout::{Layout, PieceShape, Reach};
use crate::assembly::Placement;
use crate::catalog::Shape;
use crate::geom::{Body, Cell};

/// Rounds of repairs before what is still apart is left out.
const ROUNDS: usize = 8;

/// Pieces across a slope and its neighbour tried, best first, before the
/// pair is given up ([`Layout::retile_pair`]).
const ACROSS_TRIES: usize = 6;

/// How two pieces of a retile meet: side by side, or only at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Meet {
    Side,
    Corner,
}

/// A repair: the piece to take out (for a grown one), and the piece to lay.
struct Fix {
    replaces: Option<u32>,
    placement: Placement,
    body: Body,
    extra: usize,
}

impl Layout<'_> {
    /// The bodies of laid pieces: the pieces of each, largest body (by
    /// cells) first.
    pub fn bodies(&mut self) -> Vec<Vec<u32>> {
        let mut by_root: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for i in 0..self.pieces.len() as u32 {
            if !self.pieces[i as usize].gone {
                let r = self.uf.find(i);
                by_root.entry(r).or_default().push(i);
            }
        }
        let mut bodies: Vec<Vec<u32>> = by_root.into_values().collect();
        let volume = |b: &Vec<u32>, l: &Layout| -> i32 {
            b.iter().map(|&i| l.pieces[i as usize].body.volume()).sum()
        };
        let mut keyed: Vec<(i32, Vec<u32>)> =
            bodies.drain(..).map(|b| (volume(&b, self), b)).collect();
        keyed.sort_by(|a, b| b.0.cmp(&a.0).then(a.1[0].cmp(&b.1[0])));
        keyed.into_iter().map(|(_, b)| b).collect()
    }

    /// Joins every body to another until the pieces are one body; leaves
    /// out the bodies nothing joins.
    pub fn join(&mut self, rng: &mut impl rand::Rng) {
        self.rebuild_bodies();
        // Side by side first; last, a body that meets the rest only at a
        // corner (a thin ear's tip one stud across, touching the ear along
        // an edge): the two pieces there are laid again with one across
        // the corner, over cells the surface passes through.
        for meet in [Meet::Side, Meet::Corner] {
            if self.join_rounds(rng, meet) {
                return;
            }
        }
        let bodies = self.bodies();
        for body in bodies.iter().skip(1) {
            let mut cells = 0;
            let mut first: Option<Cell> = None;
            for &i in body {
                let b = self.pieces[i as usize].body;
                cells += b.cells().filter(|&q| self.must.get(q)).count();
                first = Some(first.map_or(b.bbox.min, |f| f.min(b.bbox.min)));
                self.remove(i);
            }
            if let Some(at) = first {
                self.repairs
                    .leave_out(at, cells, "no piece can join it to the rest of the build");
            }
        }
        self.rebuild_bodies();
    }

    /// Rounds of repairs of the bodies apart, those `meet` allows, until
    /// one makes no progress; whether the pieces are one body.
    fn join_rounds(&mut self, rng: &mut impl rand::Rng, meet: Meet) -> bool {
        for _ in 0..ROUNDS {
            let bodies = self.bodies();
            if bodies.len() <= 1 {
                return true;
            }
            let mut progress = false;
            // Smallest loose body first: it has the fewest ways out.
            for body in bodies[1..].iter().rev() {
                let root = self.uf.find(body[0]);
                if self.uf.find(bodies[0][0]) == root {
                    continue;
                }
                let fix = match meet {
                    Meet::Side => self.find_fix(body, root),
                    Meet::Corner => None,
                };
                if let Some(fix) = fix {
                    if let Some(old) = fix.replaces {
                        self.remove(old);
                    }
                    self.repairs.extra_cells += fix.extra;
                    self.place(fix.placement, fix.body, None);
                    self.stats.joins += 1;
                    progress = true;
                } else if self.retile_across(body, root, rng, meet) {
                    self.stats.joins += 1;
                    progress = true;
                }
            }
            self.rebuild_bodies();
            if !progress {
                break;
            }
        }
        self.bodies().len() <= 1
    }

    /// The repair that joins the body `body` (root `root`) to another with
    /// the fewest cells outside the model.
    fn find_fix(&mut self, body: &[u32], root: u32) -> Option<Fix> {
        let mut best: Option<Fix> = None;
        let roots: Vec<u32> = (0..self.pieces.len() as u32)
            .map(|i| self.uf.find(i))
            .collect();
        let rects: Vec<PieceShape> = self
            .shapes
            .iter()
            .filter(|s| s.part.spec().shape == Shape::Rect)
            .cloned()
            .collect();
        for &i in body {
            let p = self.pieces[i as usize];
            if p.gone {
                continue;
            }
            // Grow the piece itself.
            if p.placement.part.spec().shape == Shape::Rect {
                for s in &rects {
                    let h = s.body_at(Cell::new(0, 0, 0)).bbox.sz;
                    if h != p.body.bbox.sz {
                        continue;
                    }
                    let (fx, fy) = s.part.spec().footprint(s.rot);
                    let b = p.body.bbox;
                    for ox in b.min.x + b.sx - fx..=b.min.x {
                        for oy in b.min.y + b.sy - fy..=b.min.y {
                            let origin = Cell::new(ox, oy, b.min.z);
                            self.consider(s, origin, Some(i), (root, &roots), &mut best);
                        }
                    }
                }
            }
            // A piece on top of it, or under it.
            for s in &rects {
                let nb = s.body_at(Cell::new(0, 0, 0));
                let h = nb.bbox.sz;
                let (fx, fy) = s.part.spec().footprint(s.rot);
                let b = p.body;
                for t in b.studs.cells() {
                    for ox in t.x - fx + 1..=t.x {
                        for oy in t.y - fy + 1..=t.y {
                            self.consider(
                                s,
                                Cell::new(ox, oy, t.z + 1),
                                None,
                                (root, &roots),
                                &mut best,
                            );
                        }
                    }
                }
                for t in b.tubes.cells() {
                    for ox in t.x - fx + 1..=t.x {
                        for oy in t.y - fy + 1..=t.y {
                            self.consider(
                                s,
                                Cell::new(ox, oy, t.z - h),
                                None,
                                (root, &roots),
                                &mut best,
                            );
                        }
                    }
                }
            }
        }
        best
    }

    /// Lays again a piece of the body `body` (root `root`) and a piece of
    /// another body beside it in the same layers, with a piece across the
    /// two first, the rest of their voxels as the layout would: for a body
    /// that meets the rest side by side (a handle against a wall). Kept
    /// only if it joins the body to another; undone otherwise.
    fn retile_across(
        &mut self,
        body: &[u32],
        root: u32,
        rng: &mut impl rand::Rng,
        meet: Meet,
    ) -> bool {
        let roots: Vec<u32> = (0..self.pieces.len() as u32)
            .map(|i| self.uf.find(i))
            .collect();
        // The body's bricks and plates first; then its slopes (a thin ear's
        // tip may be two slopes one over the other, beside the rest), laid
        // again with a piece that may fill the cells the surface passes
        // through, where the slope's face was.
        for slopes in [false, true] {
            if self.retile_pieces(body, root, &roots, rng, (meet, slopes)) {
                return true;
            }
        }
        false
    }

    /// [`Layout::retile_across`] for the pieces of `body` that are slopes
    /// (`slopes`) or are not.
    fn retile_pieces(
        &mut self,
        body: &[u32],
        root: u32,
        roots: &[u32],
        rng: &mut impl rand::Rng,
        (meet, slopes): (Meet, bool),
    ) -> bool {
        let mut tries = 0;
        for &h in body {
            let hb = self.pieces[h as usize].body;
            // A piece an earlier repair of this round took out is gone.
            if self.pieces[h as usize].gone
                || (self.pieces[h as usize].placement.part.spec().shape != Shape::Rect) != slopes
            {
                continue;
            }
            let mut others: Vec<u32> = Vec::new();
            let near: &[(i32, i32)] = match meet {
                Meet::Side => &[(1, 0), (-1, 0), (0, 1), (0, -1)],
                Meet::Corner => &[(1, 1), (1, -1), (-1, 1), (-1, -1)],
            };
            for q in hb.cells() {
                for n in near.iter().map(|d| q.offset(d.0, d.1, 0)) {
                    if let Some(w) = self.owner_of(n) {
                        let wb = self.pieces[w as usize].body;
                        // The other piece may be a slope: a long slope laid
                        // where a thin wing meets the fuselage may be all
                        // the wing touches (the glider at 24 studs,
                        // `--slopes --plates`: both wings were left out).
                        if roots[w as usize] != root
                            && !others.contains(&w)
                            && wb.bbox.min.z < hb.bbox.min.z + hb.bbox.sz
                            && hb.bbox.min.z < wb.bbox.min.z + wb.bbox.sz
                        {
                            others.push(w);
                        }
                    }
                }
            }
            for w in others {
                tries += 1;
                if tries > 64 {
                    return false;
                }
                if self.retile_pair((h, w), (root, roots), rng, (meet, slopes)) {
                    return true;
                }
            }
        }
        false
    }

    /// [`Layout::retile_across`] for pieces `h` (of the body `root`, whose
    /// pieces' roots before the repair are `roots`) and `w`. With `slopes`
    /// (`h` is a slope), the piece across may fill cells the surface
    /// passes through (where the slope's face was), and the pieces across
    /// are tried best first, [`ACROSS_TRIES`] of them: the best may cover
    /// the cells of the two and join neither body to the other, where the
    /// slope alone held the pieces over it.
    fn retile_pair(
        &mut self,
        (h, w): (u32, u32),
        (root, roots): (u32, &[u32]),
        rng: &mut impl rand::Rng,
        (meet, slopes): (Meet, bool),
    ) -> bool {
        let (hp, wp) = (self.pieces[h as usize], self.pieces[w as usize]);
        let cells: Vec<Cell> = hp
            .body
            .cells()
            .chain(wp.body.cells())
            .filter(|&q| self.must.get(q))
            .collect();
        self.remove(h);
        self.remove(w);
        let loose = meet == Meet::Corner || slopes;
        let tries = if slopes { ACROSS_TRIES } else { 1 };
        for (k, (p, b)) in self
            .across(&hp.body, &wp.body, loose)
            .into_iter()
            .take(tries)
            .enumerate()
        {
            // The bodies again without what the last try laid.
            if k > 0 {
                self.rebuild_bodies();
            }
            if self.lay_across((p, b), &cells, (root, roots), rng) {
                return true;
            }
        }
        self.restore(h);
        self.restore(w);
        self.rebuild_bodies();
        false
    }

    /// Lays the piece `p` (body `b`) across two pieces taken out, and the
    /// rest of their `cells` as the layout would; kept if the cells are
    /// covered and the new pieces join the body `root` to another (whose
    /// pieces' roots before the repair are `roots`), else undone (the
    /// bodies are then not rebuilt).
    fn lay_across(
        &mut self,
        (p, b): (Placement, Body),
        cells: &[Cell],
        (root, roots): (u32, &[u32]),
        rng: &mut impl rand::Rng,
    ) -> bool {
        let first_new = self.pieces.len() as u32;
        let extra_before = self.repairs.extra_cells;
        // Cells outside the model: only where the two meet at a corner, or
        // where a slope's face was.
        self.repairs.extra_cells += b.cells().filter(|&q| !self.must.get(q)).count();
        self.place(p, b, None);
        for &c in cells {
            if self.owner_of(c).is_none() {
                if let Some(cand) = self.choose(c, rng) {
                    self.repairs.extra_cells += cand.extra;
                    self.place(cand.placement, cand.body, None);
                }
            }
        }
        let covered = cells.iter().all(|&c| self.owner_of(c).is_some());
        self.rebuild_bodies();
        let r = self.uf.find(first_new);
        let alone = roots.iter().filter(|&&x| x == root).count() == 1;
        let (mut mine, mut other) = (alone, false);
        for i in 0..first_new {
            if self.pieces[i as usize].gone || self.uf.find(i) != r {
                continue;
            }
            if roots[i as usize] == root {
                mine = true;
            } else {
                other = true;
            }
        }
        let ok = covered && mine && other;
        if !ok {
            for i in first_new..self.pieces.len() as u32 {
                if !self.pieces[i as usize].gone {
                    self.remove(i);
                }
            }
            self.repairs.extra_cells = extra_before;
        }
        ok
    }

    /// The bricks (and plates) over the model's free voxels in the layers
    /// `a` and `b` share that reach into the boxes of both, the biggest
    /// first; `loose` (where they meet at a corner, or one is a slope),
    /// over the cells the surface passes through too, the fewest of those
    /// first.
    fn across(&self, a: &Body, b: &Body, loose: bool) -> Vec<(Placement, Body)> {
        // Ranked by (fewest cells outside, most cells): all inside side by
        // side.
        let mut found: Vec<((i32, i32), Placement, Body)> = Vec::new();
        let ab = a.bbox;
        let lo = ab.min.z.max(b.bbox.min.z);
        let hi = (ab.min.z + ab.sz).min(b.bbox.min.z + b.bbox.sz);
        for shape in self.shapes.iter() {
            if shape.part.spec().shape != Shape::Rect {
                continue;
            }
            let (fx, fy) = shape.part.spec().footprint(shape.rot);
            let sz = shape.body_at(Cell::new(0, 0, 0)).bbox.sz;
            for oz in (lo..=hi - sz).filter(|z| z.rem_euclid(self.phase) == 0) {
                for ox in ab.min.x - fx + 1..ab.min.x + ab.sx {
                    for oy in ab.min.y - fy + 1..ab.min.y + ab.sy {
                        let origin = Cell::new(ox, oy, oz);
                        let body = shape.body_at(origin);
                        if !body.bbox.intersects(&ab) || !body.bbox.intersects(&b.bbox) {
                            continue;
                        }
                        let v = if loose {
                            let placement = Placement::new(shape.part, origin, shape.rot);
                            match self.fits(&placement, &body, Reach::Near) {
                                Some((inside, near, 0)) => (-(near as i32), inside as i32),
                                _ => continue,
                            }
                        } else if body.cells().all(|q| self.must.get(q) && self.free(q)) {
                            (0, body.volume())
                        } else {
                            continue;
                        };
                        found.push((v, Placement::new(shape.part, origin, shape.rot), body));
                    }
                }
            }
        }
        // Best first; of equal ones, the first found.
        found.sort_by_key(|x| std::cmp::Reverse(x.0));
        found.into_iter().map(|(_, p, b)| (p, b)).collect()
    }

    /// Fills the gaps between piece `p` and the pieces under it and over
    /// it in its footprint: new pieces there join it to what is below and
    /// above, so that neither it nor they must go into a gap too tight to
    /// reach. Whether anything was laid.
    pub fn fill_under(&mut self, p: &Placement, rng: &mut impl rand::Rng) -> bool {
        let Some(id) = self.owner_of(p.body(self.layer_ldu).key()) else {
            return false;
        };
        let body = self.pieces[id as usize].body;
        let (_, _, nz) = self.must.dims();
        let mut gap: Vec<Cell> = Vec::new();
        // Under it, and over it: each column up to the next piece.
        for (start, dz) in [(body.tubes, -1), (body.studs, 1)] {
            for t in start.cells() {
                let mut col = Vec::new();
                let mut q = t.offset(0, 0, dz);
                while q.z >= 0 && q.z < nz && self.owner_of(q).is_none() {
                    col.push(q);
                    q = q.offset(0, 0, dz);
                }
                // A gap ends on a piece, or under it on the table: a
                // pillar may stand there (inside a hollow build, or in a
                // cavity the table closes).
                let on_table = dz < 0 && q.z < 0;
                if (q.z >= 0 && q.z < nz) || on_table {
                    // The inside of a hollow build under the piece becomes
                    // a pillar: nothing else can reach the piece there once
                    // the shell closes. Over it, the hollow stays.
                    if dz < 0 {
                        for &c in &col {
                            if self.kept_empty(c) {
                                self.released.insert(c);
                            }
                        }
                    }
                    gap.extend(col);
                }
            }
        }
        gap.sort_by_key(|c| (c.z, c.y, c.x));
        let mut laid = false;
        for c in gap {
            if self.owner_of(c).is_some() {
                continue;
            }
            if let Some(cand) = self.fill_candidate(c, rng) {
                self.repairs.extra_cells += cand.extra;
                self.place(cand.placement, cand.body, None);
                self.stats.fills += 1;
                laid = true;
            }
        }
        laid
    }

    /// Keeps shape `s` at `origin` in `best` if it joins the body `root`
    /// to another (taking the place of piece `replaces`) with fewer cells
    /// outside the model.
    fn consider(
        &self,
        s: &PieceShape,
        origin: Cell,
        replaces: Option<u32>,
        (root, roots): (u32, &[u32]),
        best: &mut Option<Fix>,
    ) {
        let body = s.body_at(origin);
        let mut extra = 0;
        for q in body.cells() {
            if !self.must.in_bounds(q) || self.kept_empty(q) || self.shaded(q) {
                return;
            }
            match self.owner_of(q) {
                None => {}
                Some(o) if Some(o) == replaces => continue,
                Some(_) => return,
            }
            if self.must.get(q) {
                continue;
            }
            extra += 1;
            if best.as_ref().is_some_and(|b| extra >= b.extra) {
                return;
            }
        }
        if replaces.is_some() && extra == 0 {
            return; // the same piece
        }
        let placement = Placement::new(s.part, origin, s.rot);
        let mut joins_mine = false;
        let mut joins_other = false;
        let below = self.below(&body);
        let above = self.above(&body);
        let ok = |o: u32, lower: bool| {
            let a = &self.pieces[o as usize].placement;
            let u = self.layer_ldu;
            if lower {
                self.book
                    .joint(a, &placement, crate::grammar::Dir::Up, u)
                    .is_some()
                    || self
                        .book
                        .joint(&placement, a, crate::grammar::Dir::Down, u)
                        .is_some()
            } else {
                self.book
                    .joint(a, &placement, crate::grammar::Dir::Down, u)
                    .is_some()
                    || self
                        .book
                        .joint(&placement, a, crate::grammar::Dir::Up, u)
                        .is_some()
            }
        };
        for (list, lower) in [(&below, true), (&above, false)] {
            for &o in list.iter() {
                if Some(o) == replaces || !ok(o, lower) {
                    continue;
                }
                if roots[o as usize] == root {
                    joins_mine = true;
                } else {
                    joins_other = true;
                }
            }
        }
        // A grown piece keeps its own body through itself.
        if (joins_mine || replaces.is_some()) && joins_other {
            *best = Some(Fix {
                replaces,
                placement,
                body,
                extra,
            });
        }
    }
}
