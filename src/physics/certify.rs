//! Step certificates: an equilibrium of the pieces placed so far, kept
//! from step to step.
//!
//! A step **stands** when its pieces have an equilibrium under gravity
//! with no hand force and every stud joint within its capacity (the safe
//! theorem of rigid-block analysis: if the contacts can carry the loads
//! in some way, the structure stands). Any method may find one; what says
//! "stands" is a check of the one found against every equation and bound.
//!
//! The check keeps the equilibrium found for the step before. A step adds
//! pieces; their weight must be carried, and only the forces near them
//! need change: the change is looked for among the new pieces, ways down
//! from each to the ground (near its plumb line, and lowest first) and
//! ways to the group's outermost grounded pieces (a weight anywhere
//! shifts the reactions under the whole group:
//! a head held out by a support column at its far side needs that
//! column's way down), as a small linear program whose unknowns are the
//! changes to those forces (the contacts among those pieces and their
//! grounds), bounded so that the new forces stay within their own bounds
//! (compression pushes, tension pulls at most a stud's capacity), with
//! every other force held as it was. Where no change is found, the
//! solver's proof of that (a virtual motion of the region's pieces in
//! which the weights do work and no force left free can resist) names the
//! pieces that move, and the region widens by a ring of contacts around
//! them (more rings where one adds no piece), up to the whole group:
//! there the program is exact (every force of the group may change), and
//! no change found means no equilibrium exists: the step fails. A change
//! found is added and checked, piece by piece over the whole group,
//! before the step is said to stand.
//!
//! The programs stop at a duality gap of 1e-4 rather than 1e-8: any
//! change that balances the pieces within their bounds will do, its cost
//! only steers it toward pushes (the check, not the solver, says whether
//! it balances; a change that does not is [`Tried::Trouble`] and the
//! region widens). On the bunny at 64 studs, seed 1, the check of its
//! shored build (251 steps): programs 16.4 s with the old rings (around
//! every piece of the region: 104 regions of 464 pieces on average at the
//! second try), 14.4 s widened around the moved pieces (112 of 378), 13.3
//! s with the looser gap (about 23 iterations a program, was 30).
//!
//! They stop earlier still: once the solver's relative primal residual
//! (against the norms of the data and of the iterate) is under a
//! hundredth and the iterate is headed for an answer rather than a
//! proof that none exists ([`EARLY_RESIDUAL`]), it
//! is settled ([`Certifier::settle`]: clamped to its bounds, then moved
//! by the least change that closes every piece's equations) and checked
//! like any answer; one that does not check is solved again, stopped at
//! a hundredth of that residual, then to the end. A program's second
//! half of its iterations went in closing residuals far below the
//! check's tolerance: on the bunny at 72 studs (5,025 pieces) the stage
//! went from 34.7 s to 18.5 s (idle cores). Of its 453 programs 172
//! found no change (their proofs widen the region) and 281 stopped
//! early; 15 of those did not settle, and tried again 7 settled and 8
//! had no answer (an iterate can look near one before the solver sees
//! there is none); none ran to its end.
//!
//! A group found with no equilibrium keeps the solver's proof of that, as
//! a motion found again and checked ([`Certifier::still_fails`]): the
//! steps after it that fail by the same motion need no program.
//!
//! A new piece whose weight pushes alone can carry down to the ground
//! needs no program (see [`Certifier::spread_down`]): on the bunny at 48
//! studs 27% of the new pieces the programs were asked about (419 of
//! 1,564), at 64 studs 21% (743 of 3,554).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use super::groups::Job;
use super::model::{Rect, Structure, CAP};
use super::{Params, PieceStress};

/// Regions tried before the whole group: the first, and each widening.
const TRIES: usize = 5;

/// The most rings of contacts a widening adds around the pieces the
/// last region's proof moved (fewer where fewer add a piece).
const WIDEST: usize = 8;

/// A ring holding this share of the group is the whole group.
const WHOLE_SHARE: f64 = 0.9;

/// The directions on the table in which the group's outermost grounded
/// pieces join the region (see [`Certifier::ways_to_footing`]).
const FOOTING_DIRECTIONS: [(f64, f64); 8] = [
    (1.0, 0.0),
    (-1.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
    (1.0, 1.0),
    (1.0, -1.0),
    (-1.0, 1.0),
    (-1.0, -1.0),
];

/// Cost of a unit of compression, against 1 for a unit of tension: the
/// change found pushes rather than pulls, keeping clutch for later steps.
const PUSH_COST: f64 = 1e-3;

/// A region's program is stopped early, once the solver's relative
/// primal residual (against the norms of the data and of the iterate) is
/// under this and
/// its homogeneous embedding's kappa/tau ratio is as small (an iterate
/// headed for an answer, not for a proof that there is none); the
/// iterate is then settled (see [`Certifier::settle`]) and checked like
/// any answer. On the bunny at 72 studs a program's last half of its
/// iterations went in closing residuals the check does not need.
const EARLY_RESIDUAL: f64 = 1e-2;

/// Rounds of [`Certifier::settle`]: each fixes the forces its step would
/// take past a bound at that bound, or frees a fixed one the step would
/// move back inside, and solves again.
const SETTLE_ROUNDS: usize = 8;

/// A piece's equation is closed by [`Certifier::settle`] within this
/// (forces in clutch capacities: a millionth of the check's tolerance for
/// the lightest part, a plate 1 x 1).
const CLOSED: f64 = 1e-12;

/// The least distance to a bound by which [`Certifier::settle`] weighs a
/// force's change, so that forces at a bound still move when only they
/// can close a residual.
const SETTLE_FLOOR: f64 = 1e-3;

/// What the certificate says of a group after a step.
pub(super) enum Verdict {
    /// It stands: each piece's stress in the equilibrium found, in the
    /// group's order.
    Stands(Vec<PieceStress>),
    /// No equilibrium exists (the exact program has none).
    Fails,
    /// The solver gave no answer.
    Unknown,
}

/// The forces of the pieces placed so far (see the module docs).
pub(super) struct Certifier<'a> {
    s: &'a Structure,
    /// A piece's equations hold within this share of its weight.
    tol: f64,
    /// Per contact, its first force (a face's four corners, then its
    /// studs); per piece, its first ground force at `goff` (the corners of
    /// its bottom on the ground, then its tubes on a baseplate).
    coff: Vec<usize>,
    goff: Vec<usize>,
    f: Vec<f64>,
    /// Per piece, its contacts.
    touching: Vec<Vec<usize>>,
    /// Scratch: per piece, its place in the region (`u32::MAX`: none).
    local: Vec<u32>,
    /// Per piece, whether it is placed: only contacts between placed
    /// pieces carry forces.
    on: Vec<bool>,
    /// The pieces before this one are placed, at least (see
    /// [`Certifier::place_to`]).
    placed_to: usize,
    /// Certificates found, per region tried (the last: the whole group).
    pub found: [usize; TRIES + 1],
    /// Pieces in the regions of the certificates found, summed.
    pub region_pieces: usize,
    /// A region's program past this gives no answer (see
    /// [`Certifier::until`]).
    deadline: Option<std::time::Instant>,
    /// Per piece, its virtual motion in the last proof that its group has
    /// no equilibrium (its lift at its centre of mass, and its tilts along
    /// x and y: the weights of its three equations); zero for a piece no
    /// proof moves. See [`Certifier::still_fails`].
    proof: Vec<[f64; 3]>,
    /// Per piece, whether its `proof` is still the solver's (see
    /// [`Certifier::keep_proof`]).
    raw: Vec<bool>,
}

/// One unknown of a region's program: which force, where, and how it acts.
#[derive(Debug, Clone, Copy)]
struct Var {
    /// Index into the forces.
    at: usize,
    /// Where it acts.
    point: (f64, f64),
    /// The piece it pushes up (pulls down, for a tension) and the piece it
    /// pushes down (pulls up), if any.
    up: usize,
    down: Option<usize>,
    tension: bool,
}

impl<'a> Certifier<'a> {
    pub(super) fn new(s: &'a Structure, params: &Params) -> Certifier<'a> {
        let n = s.loads.len();
        let mut coff = Vec::with_capacity(s.contacts.len());
        let mut next = 0;
        let mut touching = vec![Vec::new(); n];
        for (k, c) in s.contacts.iter().enumerate() {
            coff.push(next);
            next += if c.face.is_some() { 4 } else { 0 } + c.studs.len();
            touching[c.below].push(k);
            touching[c.above].push(k);
        }
        let mut goff = Vec::with_capacity(n);
        for l in &s.loads {
            goff.push(next);
            next += if l.ground.is_some() { 4 } else { 0 } + l.ground_studs.len();
        }
        Certifier {
            s,
            tol: params.fall_tolerance,
            coff,
            goff,
            f: vec![0.0; next],
            touching,
            local: vec![u32::MAX; n],
            on: vec![false; n],
            placed_to: 0,
            found: [0; TRIES + 1],
            region_pieces: 0,
            deadline: None,
            proof: vec![[0.0; 3]; n],
            raw: vec![false; n],
        }
    }

    /// Stops each region's program at `deadline`: one not solved by then
    /// gives no answer ([`Verdict::Unknown`], for the caller's budget to
    /// settle), so a big group's program never runs far past it.
    pub(super) fn until(mut self, deadline: Option<std::time::Instant>) -> Self {
        self.deadline = deadline;
        self
    }

    /// Places piece `p`: its contacts with placed pieces may carry forces.
    pub(super) fn place(&mut self, p: usize) {
        self.on[p] = true;
    }

    /// Places every piece before `end` (a build order's first pieces).
    pub(super) fn place_to(&mut self, end: usize) {
        self.on[self.placed_to.min(end)..end].fill(true);
        self.placed_to = self.placed_to.max(end);
    }

    /// Takes piece `p` away again (its forces are those of a
    /// [`Certifier::forces`] kept from before it was placed).
    pub(super) fn remove(&mut self, p: usize) {
        self.on[p] = false;
    }

    /// The kept forces, to go back to (see [`Certifier::set_forces`]).
    pub(super) fn forces(&self) -> &[f64] {
        &self.f
    }

    /// Goes back to forces kept by [`Certifier::forces`].
    pub(super) fn set_forces(&mut self, f: &[f64]) {
        self.f.copy_from_slice(f);
    }

    /// The groups of placed pieces (joined by contacts between placed
    /// pieces) that hold a piece of `new`, each with its pieces of `new`
    /// (sorted).
    pub(super) fn groups_with(&mut self, new: &[usize]) -> Vec<(Job, Vec<usize>)> {
        let s = self.s;
        let mut out = Vec::new();
        let mut seen: Vec<usize> = Vec::new();
        for &start in new {
            if self.local[start] != u32::MAX || !self.on[start] {
                continue;
            }
            self.local[start] = 0;
            seen.push(start);
            let (mut pieces, mut contacts) = (vec![start], Vec::new());
            let mut i = 0;
            while i < pieces.len() {
                let p = pieces[i];
                i += 1;
                for (k, q) in placed_contacts(s, &self.touching[p], &self.on, p) {
                    if s.contacts[k].below == p {
                        contacts.push(k);
                    }
                    if self.local[q] == u32::MAX {
                        self.local[q] = 0;
                        seen.push(q);
                        pieces.push(q);
                    }
                }
            }
            pieces.sort_unstable();
            contacts.sort_unstable();
            let mut mine: Vec<usize> = new
                .iter()
                .copied()
                .filter(|p| pieces.binary_search(p).is_ok())
                .collect();
            mine.sort_unstable();
            let grounded = pieces.iter().any(|&p| s.grounded(p));
            let job = Job {
                pieces,
                contacts,
                grounded,
            };
            out.push((job, mine));
        }
        for p in seen {
            self.local[p] = u32::MAX;
        }
        out
    }

    /// The forces of contact `k`, or of piece `p`'s ground, with the piece
    /// pushed up first.
    fn contact_vars(&self, k: usize, out: &mut Vec<Var>) {
        let c = &self.s.contacts[k];
        let (up, down) = (c.above, Some(c.below));
        push_vars(self.coff[k], c.face, &c.studs, up, down, out);
    }

    fn ground_vars(&self, p: usize, out: &mut Vec<Var>) {
        let l = &self.s.loads[p];
        push_vars(self.goff[p], l.ground, &l.ground_studs, p, None, out);
    }

    /// Every force on piece `p` (its contacts with placed pieces, its
    /// ground) into `vars`, cleared first.
    fn all_vars(&self, p: usize, vars: &mut Vec<Var>) {
        vars.clear();
        for &k in &self.touching[p] {
            let c = &self.s.contacts[k];
            if self.on[c.below] && self.on[c.above] {
                self.contact_vars(k, vars);
            }
        }
        self.ground_vars(p, vars);
    }

    /// Piece `p`'s equations: its weight less the forces on it (vertical,
    /// then the moments about its centre of mass), counting contacts with
    /// pieces before `end` only.
    fn residual(&self, p: usize, vars: &mut Vec<Var>) -> [f64; 3] {
        let l = &self.s.loads[p];
        let mut r = [l.weight, 0.0, 0.0];
        self.all_vars(p, vars);
        for v in vars.iter() {
            let f = self.f[v.at] * sign(v, p);
            r[0] -= f;
            r[1] -= f * (v.point.0 - l.com.0);
            r[2] -= f * (v.point.1 - l.com.1);
        }
        r
    }

    /// Whether piece `p`'s equations hold (within [`Params::fall_tolerance`]
    /// of its weight, a moment within that force at its far edge).
    fn balanced(&self, p: usize, vars: &mut Vec<Var>) -> bool {
        let l = &self.s.loads[p];
        let r = self.residual(p, vars);
        let e = &l.extent;
        let reach = (e.x1 - e.x0).max(e.y1 - e.y0).max(1.0);
        let t = self.tol * l.weight;
        r[0].abs() <= t && r[1].abs() <= t * reach && r[2].abs() <= t * reach
    }

    /// Adds the weight of the pieces `new` to the kept forces as pushes
    /// alone, handed down from piece to piece to the ground: each piece on
    /// the way takes the loads from above at their resultant's point and
    /// passes them on to the faces under it (and its ground) at that
    /// point, where one face holds it, else shared among three of their
    /// corners whose triangle holds it (with `straight`, only on a face
    /// that holds it: the weight goes straight down). The pushes added
    /// (force, amount); none, changing nothing, where a piece's resultant
    /// lies outside every such triangle (only a pull at its studs could
    /// hold it: an overhang, for a program). Compression
    /// only grows, so every other force stays within its bounds and every
    /// piece's clutch used stays as it was; each piece the loads pass
    /// through is checked balanced.
    pub(super) fn spread_down(
        &mut self,
        new: &[usize],
        straight: bool,
    ) -> Option<Vec<(usize, f64)>> {
        let s = self.s;
        // Per piece, the loads on it: down, and their moments about the
        // origin; taken highest first, so a piece's loads are all in.
        let mut load: std::collections::HashMap<usize, [f64; 3]> = Default::default();
        let mut queue = std::collections::BinaryHeap::new();
        for &p in new {
            let l = &s.loads[p];
            let e = load.entry(p).or_insert([0.0; 3]);
            e[0] += l.weight;
            e[1] += l.weight * l.com.0;
            e[2] += l.weight * l.com.1;
            queue.push((l.z, p));
        }
        let mut added: Vec<(usize, f64)> = Vec::new();
        let mut through = Vec::new();
        let mut vars = Vec::new();
        let mut held = true;
        while let Some((_, q)) = queue.pop() {
            let Some([w, mx, my]) = load.remove(&q) else {
                continue;
            };
            through.push(q);
            self.below_vars(q, &mut vars);
            let Some(shares) = (w > 0.0)
                .then(|| pushes_holding((mx / w, my / w), w, &vars, straight))
                .flatten()
            else {
                held = false;
                break;
            };
            for (i, x) in shares {
                let v = vars[i];
                self.f[v.at] += x;
                added.push((v.at, x));
                if let Some(b) = v.down {
                    let e = load.entry(b).or_insert([0.0; 3]);
                    e[0] += x;
                    e[1] += x * v.point.0;
                    e[2] += x * v.point.1;
                    queue.push((s.loads[b].z, b));
                }
            }
        }
        let mut scratch = Vec::new();
        if held && through.iter().all(|&p| self.balanced(p, &mut scratch)) {
            return Some(added);
        }
        for (at, x) in added {
            self.f[at] -= x;
        }
        None
    }

    /// The verdict on group `job` of the placed pieces (see
    /// [`Certifier::place`]), of which `new` (sorted) were placed since the
    /// last verdict: the kept forces changed near the new pieces (see the
    /// module docs).
    pub(super) fn certify(&mut self, job: &Job, new: &[usize]) -> Verdict {
        let mut vars = Vec::new();
        // The kept forces must hold the old pieces already; if not (the
        // group failed before), only the whole group can mend them.
        let kept = job
            .pieces
            .iter()
            .all(|&p| new.binary_search(&p).is_ok() || self.balanced(p, &mut vars));
        let whole_at = (WHOLE_SHARE * job.pieces.len() as f64) as usize;
        // Mostly new (a group's first step): the whole group at once.
        let near = kept && new.len() < whole_at;
        if near {
            let new = new.to_vec();
            // The new pieces whose weight pushes alone carry down are
            // placed so. The program looks for a change for the rest:
            // first among them and their ways down alone, then among
            // every new piece's (a counterweight's pushes may have to
            // move for the piece it holds out).
            let mut pushed = Vec::new();
            let mut rest = Vec::new();
            for &p in &new {
                match self.spread_down(&[p], false) {
                    Some(added) => pushed.extend(added),
                    None => rest.push(p),
                }
            }
            if rest.is_empty() {
                self.found[0] += 1;
                return Verdict::Stands(self.stress(job));
            }
            if rest.len() < new.len() {
                let region = self.first_region(rest, job);
                if let Tried::Stands(stress) = self.try_region(&region, job) {
                    self.found[0] += 1;
                    self.region_pieces += region.len();
                    return Verdict::Stands(stress);
                }
                // Taken back: the pushes may run where no region reaches.
                for (at, x) in pushed {
                    self.f[at] -= x;
                }
            }
            let mut region = self.first_region(new, job);
            let mut widened = 0;
            while region.len() < whole_at && widened < TRIES {
                let tried = self.try_region(&region, job);
                // Where no change is found, the region widens around
                // the pieces the program's proof of that moves.
                let around = match tried {
                    Tried::Stands(stress) => {
                        self.found[widened] += 1;
                        self.region_pieces += region.len();
                        return Verdict::Stands(stress);
                    }
                    Tried::None(moved, _) => moved,
                    Tried::Trouble => region.clone(),
                };
                widened += 1;
                let Some(wider) = (1..=WIDEST)
                    .map(|rings| union(&region, &self.region(&around, rings)))
                    .find(|wider| wider.len() > region.len())
                else {
                    break;
                };
                region = wider;
            }
        }
        let r = self.try_region(&job.pieces, job);
        match r {
            Tried::Stands(stress) => {
                self.found[TRIES] += 1;
                self.region_pieces += job.pieces.len();
                Verdict::Stands(stress)
            }
            Tried::None(moving, y) => {
                // The group's proof, kept for the steps after (see
                // `still_fails`).
                self.keep_proof(job, &moving, &y);
                Verdict::Fails
            }
            Tried::Trouble => Verdict::Unknown,
        }
    }

    /// Keeps a proof that group `job` has no equilibrium, from the
    /// solver's `y` (three weights a piece of the group, as
    /// [`Found::None`]'s) on the pieces it moves (`moving`, sorted), as it
    /// is: that proof holds only within the
    /// solver's tolerance, which on big groups leaves some pushes closing
    /// by as much as the largest motion, so [`Certifier::still_fails`]
    /// looks for the motion again among the pieces it moves and the new
    /// ones ([`Certifier::motion`]) when it first needs it (a check that
    /// stops at its first failure never does).
    fn keep_proof(&mut self, job: &Job, moving: &[usize], y: &[f64]) {
        for (i, &p) in job.pieces.iter().enumerate() {
            let kept = moving.binary_search(&p).is_ok();
            self.raw[p] = kept;
            self.proof[p] = if kept {
                [y[3 * i], y[3 * i + 1], y[3 * i + 2]]
            } else {
                [0.0; 3]
            };
        }
    }

    /// A virtual motion of the pieces `moving` (sorted; every other piece
    /// still) in which their weights do a unit of work and no push closes,
    /// with the least the pulls at the studs and the hands the program
    /// tolerates can resist (Farkas' program for a group's equilibrium, on
    /// those pieces; see [`Certifier::proof_holds`]): per piece, its lift
    /// and tilts; none if the solver finds none.
    fn motion(&mut self, moving: &[usize]) -> Option<Vec<[f64; 3]>> {
        let s = self.s;
        for (i, &p) in moving.iter().enumerate() {
            self.local[p] = i as u32;
        }
        let mut vars = Vec::new();
        for &p in moving {
            for &k in &self.touching[p] {
                let c = &s.contacts[k];
                let other = if c.below == p { c.above } else { c.below };
                // Each contact once: from its upper piece when both move.
                let inside = self.local[other] != u32::MAX;
                if self.on[other] && (!inside || c.above == p) {
                    self.contact_vars(k, &mut vars);
                }
            }
            self.ground_vars(p, &mut vars);
        }
        let ny = 3 * moving.len();
        let tensions = vars.iter().filter(|v| v.tension).count();
        // Per piece also a hand: what the program's tolerance lets hold it
        // at its footprint's corner that sinks most.
        let hands = ny + tensions;
        let cols = hands + moving.len();
        // Rows: the unit of work, then per force the motion's opening
        // (at least the pull's share, for a tension), then t >= 0, then
        // per piece each corner's sinking at most its hand's, and h >= 0.
        let corner_rows = 1 + vars.len() + tensions;
        let rows = corner_rows + 5 * moving.len();
        let (mut ri, mut ci, mut val) = (Vec::new(), Vec::new(), Vec::new());
        for (i, &p) in moving.iter().enumerate() {
            ri.push(0);
            ci.push(3 * i);
            val.push(s.loads[p].weight);
        }
        let mut t = ny;
        for (j, v) in vars.iter().enumerate() {
            for p in std::iter::once(v.up).chain(v.down) {
                let i = self.local[p];
                if i == u32::MAX {
                    continue;
                }
                let com = s.loads[p].com;
                let f = sign(v, p);
                for (d, x) in [1.0, v.point.0 - com.0, v.point.1 - com.1]
                    .into_iter()
                    .enumerate()
                {
                    ri.push(1 + j);
                    ci.push(3 * i as usize + d);
                    val.push(-f * x);
                }
            }
            if v.tension {
                ri.push(1 + j);
                ci.push(t);
                val.push(-1.0);
                ri.push(1 + vars.len() + (t - ny));
                ci.push(t);
                val.push(-1.0);
                t += 1;
            }
        }
        for (i, &p) in moving.iter().enumerate() {
            self.local[p] = u32::MAX;
            let l = &s.loads[p];
            for (c, at) in l.extent.corners().into_iter().enumerate() {
                let r = corner_rows + 4 * i + c;
                for (d, x) in [1.0, at.0 - l.com.0, at.1 - l.com.1]
                    .into_iter()
                    .enumerate()
                {
                    ri.push(r);
                    ci.push(3 * i + d);
                    val.push(-x);
                }
                ri.push(r);
                ci.push(hands + i);
                val.push(-1.0);
            }
            ri.push(corner_rows + 4 * moving.len() + i);
            ci.push(hands + i);
            val.push(-1.0);
        }
        let a = CscMatrix::new_from_triplets(rows, cols, ri, ci, val);
        let mut b = vec![0.0; rows];
        b[0] = -1.0;
        let mut cost = vec![0.0; cols];
        cost[ny..hands].fill(1.0);
        for (i, &p) in moving.iter().enumerate() {
            cost[hands + i] = self.tol * s.loads[p].weight;
        }
        let pm = CscMatrix::zeros((cols, cols));
        let cones = [
            SupportedConeT::ZeroConeT(1),
            SupportedConeT::NonnegativeConeT(rows - 1),
        ];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_threads(1)
            .direct_solve_method("qdldl".to_string())
            .build()
            .ok()?;
        let mut solver = DefaultSolver::new(&pm, &cost, &a, &b, &cones, settings).ok()?;
        if let Some(deadline) = self.deadline {
            solver.set_termination_callback(move |_| std::time::Instant::now() >= deadline);
        }
        solver.solve();
        if !matches!(
            solver.solution.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            return None;
        }
        let x = &solver.solution.x;
        Some(
            (0..moving.len())
                .map(|i| [x[3 * i], x[3 * i + 1], x[3 * i + 2]])
                .collect(),
        )
    }

    /// Whether group `job`, of which `new` (sorted) were placed since its
    /// last verdict, still has no equilibrium by the proof kept from an
    /// earlier step that a group of its pieces had none: a virtual motion
    /// in which the weights do more work than the joints can resist. Each
    /// new piece stays still or moves with a piece it touches, whichever
    /// its joints resist less, and the motion is checked over the whole
    /// group ([`Certifier::proof_holds`]), in time linear in its contacts.
    /// Where it holds, the new pieces' motions are kept with the proof.
    pub(super) fn still_fails(&mut self, job: &Job, new: &[usize]) -> bool {
        if job.pieces.iter().all(|&p| self.proof[p] == [0.0; 3]) {
            return false;
        }
        for &p in new {
            self.proof[p] = [0.0; 3];
        }
        let mut vars = Vec::new();
        let bound = self.push_bound(job, &mut vars);
        // The solver's proof is found again among the pieces it moves and
        // the new ones, below; a proof found so is first tried with each
        // new piece still or moving with one it touches.
        let raw: Vec<usize> = job
            .pieces
            .iter()
            .copied()
            .filter(|&p| self.raw[p])
            .collect();
        for &p in &raw {
            self.raw[p] = false;
        }
        if raw.is_empty() {
            for &p in new {
                self.follow(p, bound, &mut vars);
            }
            if self.proof_holds(job, bound, &mut vars) {
                return true;
            }
        }
        // The motion again, among the pieces it moved and the new ones (a
        // new piece joining moving pieces to still ones may make another
        // motion the one that fails).
        let mut moving: Vec<usize> = job
            .pieces
            .iter()
            .copied()
            .filter(|&p| self.proof[p] != [0.0; 3])
            .collect();
        moving = union(&moving, new);
        for &p in &moving {
            self.proof[p] = [0.0; 3];
        }
        if let Some(motion) = self.motion(&moving) {
            for (&p, m) in moving.iter().zip(motion) {
                self.proof[p] = m;
            }
            if self.proof_holds(job, bound, &mut vars) {
                return true;
            }
        }
        for &p in &moving {
            self.proof[p] = [0.0; 3];
        }
        false
    }

    /// Whether piece `p` moves in the proof kept that its group has no
    /// equilibrium (see [`Certifier::still_fails`]).
    pub(super) fn moves(&self, p: usize) -> bool {
        self.proof[p] != [0.0; 3]
    }

    /// Gives new piece `p` the motion its joints resist least: still, or
    /// moving with a piece it touches that moves.
    fn follow(&mut self, p: usize, bound: f64, vars: &mut Vec<Var>) {
        let mut best = (self.own_work(p, bound, vars), [0.0; 3]);
        let moving: Vec<usize> = placed_contacts(self.s, &self.touching[p], &self.on, p)
            .map(|(_, q)| q)
            .filter(|&q| self.proof[q] != [0.0; 3])
            .collect();
        for q in moving {
            let m = self.moving_with(q, p);
            self.proof[p] = m;
            let w = self.own_work(p, bound, vars);
            if w < best.0 {
                best = (w, m);
            }
        }
        self.proof[p] = best.1;
    }

    /// The most any push of group `job` can carry in an equilibrium with
    /// every pull within a stud's clutch: the group's weight and every
    /// stud's clutch. (The pieces whose bottoms are at or above a push's
    /// height are held by the forces from the pieces under them, and by
    /// hands, alone, so those pushes carry at most their weight and the
    /// pulls at those joints.)
    fn push_bound(&self, job: &Job, vars: &mut Vec<Var>) -> f64 {
        let mut bound = 0.0;
        for &p in &job.pieces {
            bound += self.s.loads[p].weight;
            self.below_vars(p, vars);
            bound += vars.iter().filter(|v| v.tension).count() as f64;
        }
        bound
    }

    /// The forces of piece `p`'s contacts with placed pieces under it, and
    /// of its ground: each force of a group once, from its upper piece.
    fn below_vars(&self, p: usize, vars: &mut Vec<Var>) {
        vars.clear();
        for &k in &self.touching[p] {
            let c = &self.s.contacts[k];
            if c.above == p && self.on[c.below] {
                self.contact_vars(k, vars);
            }
        }
        self.ground_vars(p, vars);
    }

    /// How far point `at` of piece `p` rises in the kept motion.
    fn lift(&self, p: usize, at: (f64, f64)) -> f64 {
        let (m, com) = (self.proof[p], self.s.loads[p].com);
        m[0] + m[1] * (at.0 - com.0) + m[2] * (at.1 - com.1)
    }

    /// Piece `q`'s kept motion, as piece `p`'s moving with it.
    fn moving_with(&self, q: usize, p: usize) -> [f64; 3] {
        let m = self.proof[q];
        [self.lift(q, self.s.loads[p].com), m[1], m[2]]
    }

    /// How far force `v` opens its joint in the kept motion: the work a
    /// unit of it does (a push's pieces part, a pull's are pressed
    /// together, where it is positive).
    fn opening(&self, v: &Var) -> f64 {
        std::iter::once(v.up)
            .chain(v.down)
            .map(|p| sign(v, p) * self.lift(p, v.point))
            .sum()
    }

    /// The most work force `v` can do against the kept motion: a pull at a
    /// stud's whole clutch (the program breaks a joint at it), a push at
    /// `bound`.
    fn resisted(&self, v: &Var, bound: f64) -> f64 {
        let a = self.opening(v);
        if a >= 0.0 {
            0.0
        } else if v.tension {
            -a
        } else {
            -a * bound
        }
    }

    /// Piece `p`'s part of the kept motion's balance: its weight's work
    /// (negative where it falls) and what its joints resist.
    fn own_work(&self, p: usize, bound: f64, vars: &mut Vec<Var>) -> f64 {
        self.all_vars(p, vars);
        let l = &self.s.loads[p];
        l.weight * self.proof[p][0]
            + self.hand(p)
            + vars.iter().map(|v| self.resisted(v, bound)).sum::<f64>()
    }

    /// Whether the kept motion proves that group `job` fails as the force
    /// program says (Farkas): the work its weights do in it (lifts times
    /// weights) is more than everything together can resist, a pull at
    /// most a stud's whole clutch, a push at most `bound`, and a hand
    /// under each piece at most what the program lets hold it without the
    /// piece falling ([`Params::fall_tolerance`] of its weight, at the
    /// corner of its footprint that sinks most). So no equilibrium has
    /// every joint below its clutch and every hand within that: the
    /// program's answer breaks a joint or drops a piece.
    fn proof_holds(&self, job: &Job, bound: f64, vars: &mut Vec<Var>) -> bool {
        let (mut work, mut scale) = (0.0, 0.0);
        for &p in &job.pieces {
            let w = self.s.loads[p].weight * self.proof[p][0];
            work += w + self.hand(p);
            scale += w.abs();
            self.below_vars(p, vars);
            work += vars.iter().map(|v| self.resisted(v, bound)).sum::<f64>();
        }
        scale > 0.0 && work < -1e-9 * scale
    }

    /// The most work a hand the program tolerates can do against piece
    /// `p`'s kept motion: [`Params::fall_tolerance`] of its weight, pushing
    /// up at the corner of its footprint that sinks most.
    fn hand(&self, p: usize) -> f64 {
        let l = &self.s.loads[p];
        let sinks = l
            .extent
            .corners()
            .iter()
            .map(|&c| -self.lift(p, c))
            .fold(0.0, f64::max);
        self.tol * l.weight * sinks
    }

    /// The first region for the new pieces `new`: they, ways down to the
    /// ground from each, one near its plumb line and one lowest first (the
    /// new weight leaves the region only through its grounds), and ways
    /// to the group's outermost grounded pieces (a weight anywhere shifts
    /// the whole group's ground reactions: its footing, a support column
    /// at its far side). Sorted.
    fn first_region(&mut self, mut new: Vec<usize>, job: &Job) -> Vec<usize> {
        for i in 0..new.len() {
            let way = self.way_down(new[i], true);
            new.extend(way);
            let way = self.way_down(new[i], false);
            new.extend(way);
        }
        let footing = self.ways_to_footing(&new, job);
        let mut region = self.region(&new, 0);
        region.extend_from_slice(&footing);
        region.sort_unstable();
        region.dedup();
        region
    }

    /// The pieces on a way through contacts from piece `from` down to a
    /// piece on the ground; empty if none. Lowest first at each turn, or
    /// with `plumb`, as near `from`'s plumb line as there is one: the
    /// piece whose extent comes nearest the line through its centre of
    /// mass first, then the lowest.
    ///
    /// The way carries the new piece's weight, and every piece on it must
    /// balance it: a way that leaves the line carries the weight's moment
    /// about it through its joints, and where it ends on a footing away
    /// from the line (the ground pushes only, under that piece) the
    /// region may hold no change; the lowest-first way reaches the ground
    /// soonest, which is where the structure sends its weight around an
    /// overhang. The first region holds both. Measured on the last
    /// support round's check of the bunny at 72 studs (5,003 pieces with
    /// its columns): lowest first alone, the first region held the
    /// step's weight in 72 of 213 steps (the rest widened to regions of
    /// 580 and then 1,050 pieces: 78 s of programs); the plumb line alone,
    /// in 182 of 225 (first regions of 350 pieces: 30 s in all), but on
    /// suzanne at 80 studs it left 8 steps to the whole group's program
    /// where lowest first left 2 (the stage 47 s, was 36 s); both, 3
    /// steps and 26 s (fandisk at 64 studs: 71 s, plumb line 53 s,
    /// both 32 s).
    fn way_down(&mut self, from: usize, plumb: bool) -> Vec<usize> {
        use std::cmp::Reverse;
        let s = self.s;
        let (x, y) = s.loads[from].com;
        // How far a piece's extent is from the plumb line, in
        // thousandths of a stud (a whole number, to order by).
        let off = |q: usize| -> i64 {
            if !plumb {
                return 0;
            }
            let e = &s.loads[q].extent;
            let dx = (e.x0 - x).max(x - e.x1).max(0.0);
            let dy = (e.y0 - y).max(y - e.y1).max(0.0);
            (dx.max(dy) * 1000.0).round() as i64
        };
        let mut heap = std::collections::BinaryHeap::new();
        let mut seen: Vec<usize> = vec![from];
        self.local[from] = from as u32;
        heap.push(Reverse((off(from), s.loads[from].z, from)));
        let mut reached = None;
        while let Some(Reverse((_, _, p))) = heap.pop() {
            if s.loads[p].ground.is_some() || !s.loads[p].ground_studs.is_empty() {
                reached = Some(p);
                break;
            }
            for (_, q) in placed_contacts(s, &self.touching[p], &self.on, p) {
                if self.local[q] == u32::MAX {
                    self.local[q] = p as u32;
                    seen.push(q);
                    heap.push(Reverse((off(q), s.loads[q].z, q)));
                }
            }
        }
        let mut way = Vec::new();
        let mut q = reached;
        while let Some(p) = q {
            way.push(p);
            let from = self.local[p] as usize;
            q = (from != p).then_some(from);
        }
        for p in seen {
            self.local[p] = u32::MAX;
        }
        way
    }

    /// The pieces on shortest ways through contacts (before `end`) from the
    /// pieces `from` to the outermost grounded pieces of `job`: the one
    /// farthest in each of eight directions of the table.
    fn ways_to_footing(&mut self, from: &[usize], job: &Job) -> Vec<usize> {
        let s = self.s;
        let on = &self.on;
        let grounded = |p: usize| {
            on[p] && (s.loads[p].ground.is_some() || !s.loads[p].ground_studs.is_empty())
        };
        let mut footing: Vec<usize> = Vec::with_capacity(8);
        for (dx, dy) in FOOTING_DIRECTIONS {
            let reach = |p: usize| dx * s.loads[p].com.0 + dy * s.loads[p].com.1;
            let far = job
                .pieces
                .iter()
                .copied()
                .filter(|&p| grounded(p))
                .max_by(|&a, &b| reach(a).total_cmp(&reach(b)));
            footing.extend(far.filter(|p| !footing.contains(p)));
        }
        if footing.is_empty() {
            return Vec::new();
        }
        // Breadth first from `from`; `local` holds where each piece was
        // reached from (the piece itself at the start).
        let mut queue = std::collections::VecDeque::new();
        let mut seen: Vec<usize> = Vec::new();
        for &p in from {
            if self.local[p] == u32::MAX {
                self.local[p] = p as u32;
                seen.push(p);
                queue.push_back(p);
            }
        }
        while let Some(p) = queue.pop_front() {
            for (_, q) in placed_contacts(s, &self.touching[p], &self.on, p) {
                if self.local[q] == u32::MAX {
                    self.local[q] = p as u32;
                    seen.push(q);
                    queue.push_back(q);
                }
            }
        }
        let mut ways = Vec::new();
        for g in footing {
            let mut q = g;
            // Back along the way until a piece of `from` or one taken.
            while self.local[q] != u32::MAX && self.local[q] as usize != q {
                ways.push(q);
                let back = self.local[q] as usize;
                // Taken: the rest of this way is too.
                self.local[q] = q as u32;
                q = back;
            }
        }
        for p in seen {
            self.local[p] = u32::MAX;
        }
        ways
    }

    /// The pieces before `end` within `rings` contacts of `from`, sorted.
    fn region(&mut self, from: &[usize], rings: usize) -> Vec<usize> {
        let mut region: Vec<usize> = Vec::with_capacity(from.len());
        for &p in from {
            if self.local[p] == u32::MAX {
                self.local[p] = 0;
                region.push(p);
            }
        }
        let mut frontier = 0;
        for _ in 0..rings {
            let stop = region.len();
            for i in frontier..stop {
                let p = region[i];
                for (_, q) in placed_contacts(self.s, &self.touching[p], &self.on, p) {
                    if self.local[q] == u32::MAX {
                        self.local[q] = 0;
                        region.push(q);
                    }
                }
            }
            frontier = stop;
        }
        for &p in &region {
            self.local[p] = u32::MAX;
        }
        region.sort_unstable();
        region
    }

    /// Looks for a change to the forces among `region` (sorted pieces of
    /// `job`) that balances them; adds it and checks the group (see
    /// [`Tried`]).
    fn try_region(&mut self, region: &[usize], job: &Job) -> Tried {
        for (i, &p) in region.iter().enumerate() {
            self.local[p] = i as u32;
        }
        let mut early = EARLY_RESIDUAL;
        let mut found = self.solve_region(region, early);
        let tried = loop {
            let (vars, change, settled) = match found {
                Found::Change(vars, change, settled) => (vars, change, settled),
                Found::None(y) => break Tried::None(moved(region, &y), y),
                Found::Trouble => break Tried::Trouble,
            };
            let before: Vec<f64> = vars.iter().map(|v| self.f[v.at]).collect();
            for (v, d) in vars.iter().zip(&change) {
                let f = &mut self.f[v.at];
                *f = (*f + d).max(0.0);
                if v.tension {
                    *f = f.min(CAP);
                }
            }
            let mut scratch = Vec::new();
            if job.pieces.iter().all(|&p| self.balanced(p, &mut scratch)) {
                break Tried::Stands(self.stress(job));
            }
            for (v, f) in vars.iter().zip(before) {
                self.f[v.at] = f;
            }
            if !settled {
                break Tried::Trouble;
            }
            // The early iterate did not settle: once more, nearer (a
            // hundredth of the residual), then to the program's end.
            early = if early == EARLY_RESIDUAL {
                EARLY_RESIDUAL * EARLY_RESIDUAL
            } else {
                0.0
            };
            found = self.solve_region(region, early);
        };
        for &p in region {
            self.local[p] = u32::MAX;
        }
        tried
    }

    /// The stress of every piece of `job` in the kept forces: its usage is
    /// its most loaded stud's tension.
    fn stress(&self, job: &Job) -> Vec<PieceStress> {
        let mut vars = Vec::new();
        job.pieces
            .iter()
            .map(|&p| {
                self.all_vars(p, &mut vars);
                let usage = vars
                    .iter()
                    .filter(|v| v.tension)
                    .map(|v| self.f[v.at])
                    .fold(0.0, f64::max);
                let mut st = PieceStress {
                    usage,
                    score: 1.0,
                    falls: false,
                    breaks: false,
                };
                st.finish();
                st
            })
            .collect()
    }

    /// An early iterate `d` of a region's program (its forces `vars`, its
    /// equations' rows of `a` and their right-hand sides `rhs`) made to
    /// balance every piece of the region: each change clamped to its
    /// force's bounds, then moved by the least change, weighed by the
    /// inverse square of each force's distance to its nearest bound (at
    /// least [`SETTLE_FLOOR`]), that closes the equations' residual; a
    /// force that step would take past a bound is fixed there and the
    /// rest solved again; where a residual is left that only a fixed
    /// force could close (the step's multipliers would move it back
    /// inside its bounds), that force goes free again; for at most
    /// [`SETTLE_ROUNDS`] rounds. Whether the answer balances is for the
    /// caller's check to say (a round whose system cannot be factored
    /// ends the rounds).
    fn settle(&self, vars: &[Var], d: &[f64], rhs: &[f64], a: &CscMatrix<f64>) -> Vec<f64> {
        let (nv, neq) = (vars.len(), rhs.len());
        let bounds: Vec<(f64, f64)> = vars
            .iter()
            .map(|v| {
                let f = self.f[v.at];
                (-f, if v.tension { CAP - f } else { f64::INFINITY })
            })
            .collect();
        let mut y: Vec<f64> = d
            .iter()
            .zip(&bounds)
            .map(|(x, &(lo, hi))| x.clamp(lo, hi))
            .collect();
        // The equations' rows of each force's column.
        let rows = |j: usize| {
            (a.colptr[j]..a.colptr[j + 1])
                .filter(|&k| a.rowval[k] < neq)
                .map(|k| (a.rowval[k], a.nzval[k]))
        };
        let mut fixed = vec![false; nv];
        // The multipliers of the last round, where it took no force past a
        // bound.
        let mut multipliers: Option<Vec<f64>> = None;
        for _ in 0..SETTLE_ROUNDS {
            let mut residual = rhs.to_vec();
            for (j, &x) in y.iter().enumerate() {
                for (i, v) in rows(j) {
                    residual[i] -= v * x;
                }
            }
            if residual.iter().all(|r| r.abs() < CLOSED) {
                break;
            }
            if let Some(m) = multipliers.take() {
                // A residual left that only a force fixed at a bound can
                // close: one the multipliers would move back inside its
                // bounds goes free again (none: nothing more to do).
                let mut freed = false;
                for j in 0..nv {
                    if !fixed[j] {
                        continue;
                    }
                    let pull: f64 = rows(j).map(|(i, v)| v * m[i]).sum();
                    let inward = if y[j] == bounds[j].0 {
                        pull < 0.0
                    } else {
                        pull > 0.0
                    };
                    if inward {
                        fixed[j] = false;
                        freed = true;
                    }
                }
                if !freed {
                    break;
                }
            }
            // The least weighted change over the free forces: the
            // quasi-definite system [W A'; A -eps I] [dx; -l] = [0; r].
            let mut at = vec![usize::MAX; nv];
            let mut by_row: Vec<Vec<(usize, f64)>> = vec![Vec::new(); neq];
            let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
            let mut free = 0;
            for j in (0..nv).filter(|&j| !fixed[j]) {
                at[j] = free;
                for (i, v) in rows(j) {
                    by_row[i].push((free, v));
                }
                let (lo, hi) = bounds[j];
                let room = (y[j] - lo).min(hi - y[j]).max(SETTLE_FLOOR);
                rowval.push(free);
                nzval.push(1.0 / (room * room));
                colptr.push(rowval.len());
                free += 1;
            }
            for (i, row) in by_row.iter().enumerate() {
                for &(j, v) in row {
                    rowval.push(j);
                    nzval.push(v);
                }
                rowval.push(free + i);
                nzval.push(-1e-12);
                colptr.push(rowval.len());
            }
            let m = free + neq;
            let kkt = CscMatrix::new(m, m, colptr, rowval, nzval);
            // No regularisation: the system is quasi-definite as it is.
            let Ok(settings) = clarabel::qdldl::QDLDLSettingsBuilder::default()
                .regularize_enable(false)
                .build()
            else {
                break;
            };
            let Ok(mut ldl) = clarabel::qdldl::QDLDLFactorisation::new(&kkt, Some(settings)) else {
                break;
            };
            let mut step = vec![0.0; m];
            step[free..].copy_from_slice(&residual);
            ldl.solve(&mut step);
            let mut past = false;
            for j in (0..nv).filter(|&j| at[j] != usize::MAX) {
                let (lo, hi) = bounds[j];
                let x = y[j] + step[at[j]];
                if !x.is_finite() {
                    return y;
                }
                if x < lo || x > hi {
                    y[j] = x.clamp(lo, hi);
                    fixed[j] = true;
                    past = true;
                } else {
                    y[j] = x;
                }
            }
            if !past {
                multipliers = Some(step[free..].to_vec());
            }
        }
        y
    }

    /// The program of a region (its pieces numbered in `self.local`): the
    /// changes to the forces among its pieces and their grounds that
    /// balance every piece of it, each force kept within its bounds.
    fn program(&self, region: &[usize]) -> Program {
        let inside = |p: usize| self.local[p] != u32::MAX;
        let mut vars = Vec::new();
        for &p in region {
            for &k in &self.touching[p] {
                let c = &self.s.contacts[k];
                // Each contact once, from its upper piece.
                if c.above == p && self.on[c.below] && self.on[c.above] && inside(c.below) {
                    self.contact_vars(k, &mut vars);
                }
            }
            self.ground_vars(p, &mut vars);
        }
        let eq = 3 * region.len();
        let nv = vars.len();
        let tensions = vars.iter().filter(|v| v.tension).count();
        let rows = eq + nv + tensions;
        let mut b = vec![0.0; rows];
        let mut scratch = Vec::new();
        for (i, &p) in region.iter().enumerate() {
            b[3 * i..3 * i + 3].copy_from_slice(&self.residual(p, &mut scratch));
        }
        let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
        let mut cost = Vec::with_capacity(nv);
        let mut next_cap = eq + nv;
        for (j, v) in vars.iter().enumerate() {
            let mut acting = vec![v.up];
            acting.extend(v.down);
            acting.sort_by_key(|&p| self.local[p]);
            for p in acting {
                let i = self.local[p] as usize;
                let com = self.s.loads[p].com;
                let f = sign(v, p);
                for (r, x) in [
                    (3 * i, f),
                    (3 * i + 1, f * (v.point.0 - com.0)),
                    (3 * i + 2, f * (v.point.1 - com.1)),
                ] {
                    rowval.push(r);
                    nzval.push(x);
                }
            }
            // The new force stays at or above 0: -d <= f.
            rowval.push(eq + j);
            nzval.push(-1.0);
            b[eq + j] = self.f[v.at];
            if v.tension {
                // And a tension at or below a stud's capacity.
                rowval.push(next_cap);
                nzval.push(1.0);
                b[next_cap] = CAP - self.f[v.at];
                next_cap += 1;
            }
            colptr.push(rowval.len());
            cost.push(if v.tension { 1.0 } else { PUSH_COST });
        }
        Program {
            a: CscMatrix::new(rows, nv, colptr, rowval, nzval),
            b,
            cost,
            eq,
            vars,
        }
    }

    /// The region's [`Certifier::program`] solved (its pieces numbered in
    /// `self.local`). With `early` above 0, the solver stops at an
    /// iterate whose residual and kappa/tau ratio are under it (see
    /// [`EARLY_RESIDUAL`]), settled.
    fn solve_region(&self, region: &[usize], early: f64) -> Found {
        let Program {
            vars,
            a,
            b,
            cost,
            eq,
        } = self.program(region);
        let nv = vars.len();
        let tensions = vars.iter().filter(|v| v.tension).count();
        let pm = CscMatrix::zeros((nv, nv));
        let cones = [
            SupportedConeT::ZeroConeT(eq),
            SupportedConeT::NonnegativeConeT(nv + tensions),
        ];
        let Ok(settings) = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_threads(1)
            .direct_solve_method("qdldl".to_string())
            .iterative_refinement_enable(false)
            .tol_gap_abs(1e-4)
            .tol_gap_rel(1e-4)
            .build()
        else {
            return Found::Trouble;
        };
        let Ok(mut solver) = DefaultSolver::new(&pm, &cost, &a, &b, &cones, settings) else {
            return Found::Trouble;
        };
        let deadline = self.deadline;
        if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            return Found::Trouble;
        }
        let near = move |i: &clarabel::solver::DefaultInfo<f64>| {
            i.iterations > 0 && i.res_primal < early && i.ktratio < early
        };
        // Stopped with the structure's other programs (its answer no
        // longer wanted: see `Structure::stop`).
        let stop = self.s.stop.clone();
        solver.set_termination_callback(move |i| {
            near(i)
                || deadline.is_some_and(|d| std::time::Instant::now() >= d)
                || stop
                    .as_ref()
                    .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
        });
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                Found::Change(vars, solver.solution.x.clone(), false)
            }
            SolverStatus::CallbackTerminated if near(&solver.info) => {
                let d = self.settle(&vars, &solver.solution.x, &b[..eq], &a);
                Found::Change(vars, d, true)
            }
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                Found::None(solver.solution.z[..eq].to_vec())
            }
            _ => Found::Trouble,
        }
    }
}

/// A load `w` at `at` carried by pushes alone at the face corners among
/// `vars` (a face's four in a row, as [`push_vars`] lists them): the
/// corners of one face that holds the point, by their bilinear weights,
/// else three corners whose triangle holds it, by its barycentric ones;
/// none where no triangle does. Each with the share of `w` it takes.
fn pushes_holding(
    at: (f64, f64),
    w: f64,
    vars: &[Var],
    straight: bool,
) -> Option<Vec<(usize, f64)>> {
    const EPS: f64 = 1e-9;
    let corners: Vec<usize> = (0..vars.len()).filter(|&i| !vars[i].tension).collect();
    for f in corners.chunks_exact(4) {
        let (lo, hi) = (vars[f[0]].point, vars[f[3]].point);
        if lo.0 - EPS <= at.0 && at.0 <= hi.0 + EPS && lo.1 - EPS <= at.1 && at.1 <= hi.1 + EPS {
            let u = ((at.0 - lo.0) / (hi.0 - lo.0)).clamp(0.0, 1.0);
            let v = ((at.1 - lo.1) / (hi.1 - lo.1)).clamp(0.0, 1.0);
            let shares = [(1.0 - u) * (1.0 - v), u * (1.0 - v), (1.0 - u) * v, u * v];
            return Some(f.iter().zip(shares).map(|(&i, x)| (i, w * x)).collect());
        }
    }
    if straight {
        return None;
    }
    let n = corners.len();
    let point = |i: usize| vars[corners[i]].point;
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                let (pa, pb, pc) = (point(a), point(b), point(c));
                let d = (pb.1 - pc.1) * (pa.0 - pc.0) + (pc.0 - pb.0) * (pa.1 - pc.1);
                if d.abs() < 1e-12 {
                    continue;
                }
                let la = ((pb.1 - pc.1) * (at.0 - pc.0) + (pc.0 - pb.0) * (at.1 - pc.1)) / d;
                let lb = ((pc.1 - pa.1) * (at.0 - pc.0) + (pa.0 - pc.0) * (at.1 - pc.1)) / d;
                let lc = 1.0 - la - lb;
                if la >= -EPS && lb >= -EPS && lc >= -EPS {
                    let l = [la.max(0.0), lb.max(0.0), lc.max(0.0)];
                    let sum: f64 = l.iter().sum();
                    return Some(
                        [a, b, c]
                            .into_iter()
                            .zip(l)
                            .map(|(i, x)| (corners[i], w * x / sum))
                            .collect(),
                    );
                }
            }
        }
    }
    None
}

/// What a region's program found.
enum Found {
    /// A change to these forces; whether it is an early iterate settled
    /// (see [`EARLY_RESIDUAL`]).
    Change(Vec<Var>, Vec<f64>, bool),
    /// None exists: the solver's proof of that, three weights a piece of
    /// the region (see [`moved`]).
    None(Vec<f64>),
    /// The solver gave no answer.
    Trouble,
}

/// A region's program: its forces' changes (the columns of `a`, costing
/// `cost`), the three equations of each piece (the first `eq` rows, equal
/// to `b`'s), then a row a force bounding it below and one a tension
/// bounding it above (at most `b`'s).
struct Program {
    vars: Vec<Var>,
    a: CscMatrix<f64>,
    b: Vec<f64>,
    cost: Vec<f64>,
    eq: usize,
}

/// What a region's change did, checked over its group.
enum Tried {
    /// It was found and balances every piece: each piece's stress.
    Stands(Vec<PieceStress>),
    /// None exists in the region: the pieces its proof moves, and the
    /// proof (as [`Found::None`]'s).
    None(Vec<usize>, Vec<f64>),
    /// The solver gave no answer, or the change found did not check.
    Trouble,
}

/// A share of the largest motion: a piece moved less than this by the
/// proof that a region has no change is taken as still.
const STILL: f64 = 1e-3;

/// The pieces of `region` that the program's proof of infeasibility `y`
/// (three rows a piece: its force and its two moments, the weights of a
/// virtual motion in which the weights do work and no force can resist)
/// moves, by more than [`STILL`] of the most moved one.
fn moved(region: &[usize], y: &[f64]) -> Vec<usize> {
    let motion: Vec<f64> = y
        .chunks(3)
        .map(|r| r.iter().fold(0.0_f64, |m, v| m.max(v.abs())))
        .collect();
    let most = motion.iter().copied().fold(0.0_f64, f64::max);
    region
        .iter()
        .zip(&motion)
        .filter(|&(_, &m)| m > STILL * most)
        .map(|(&p, _)| p)
        .collect()
}

/// The sorted union of two sorted lists of pieces.
fn union(a: &[usize], b: &[usize]) -> Vec<usize> {
    let mut u: Vec<usize> = a.iter().chain(b).copied().collect();
    u.sort_unstable();
    u.dedup();
    u
}

/// The forces from `at` of one contact (or ground) pushing `up` and, if
/// any, `down`: compression at the corners of `face`, then a tension at
/// each of `studs`.
fn push_vars(
    mut at: usize,
    face: Option<Rect>,
    studs: &[(f64, f64)],
    up: usize,
    down: Option<usize>,
    out: &mut Vec<Var>,
) {
    let corners = face.iter().flat_map(|f| f.corners()).map(|p| (p, false));
    for (point, tension) in corners.chain(studs.iter().map(|&p| (p, true))) {
        out.push(Var {
            at,
            point,
            up,
            down,
            tension,
        });
        at += 1;
    }
}

/// The contacts (from piece `p`'s `touching`) between placed pieces (`on`),
/// each with the piece on its other side.
fn placed_contacts<'x>(
    s: &'x Structure,
    touching: &'x [usize],
    on: &'x [bool],
    p: usize,
) -> impl Iterator<Item = (usize, usize)> + 'x {
    touching.iter().filter_map(move |&k| {
        let c = &s.contacts[k];
        let q = if c.below == p { c.above } else { c.below };
        (on[c.below] && on[c.above]).then_some((k, q))
    })
}

/// +1 if force `v` pushes piece `p` up, -1 if down.
fn sign(v: &Var, p: usize) -> f64 {
    let up = if v.up == p { 1.0 } else { -1.0 };
    if v.tension {
        -up
    } else {
        up
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::fixtures::counterweighted;

    /// The verdict on the whole build, placed at once.
    fn verdict(deadline: Option<std::time::Instant>) -> Verdict {
        let params = Params::default();
        let asm = counterweighted();
        let s = Structure::new(&asm, &params);
        let mut cert = Certifier::new(&s, &params).until(deadline);
        cert.place_to(asm.pieces.len());
        let mut groups = cert.groups_with(&[0, 1, 2]);
        assert_eq!(groups.len(), 1);
        let (job, new) = groups.remove(0);
        cert.certify(&job, &new)
    }

    /// A piece on the table over [0, 2], its centre of mass at 2.5 and its
    /// reach to 6, and a counterweight of weight `w1` clutched on it over
    /// [0, 1]: the pair's moment past the table's edge is 0.5 - 1.5 w1.
    fn tipping(w1: f64) -> Structure {
        use super::super::model::Load;
        let rect = |x0, x1| Rect {
            x0,
            y0: 0.0,
            x1,
            y1: 1.0,
        };
        Structure {
            loads: vec![
                Load {
                    weight: 1.0,
                    com: (2.5, 0.5),
                    extent: rect(0.0, 6.0),
                    ground: Some(rect(0.0, 2.0)),
                    ground_studs: vec![],
                    z: 0,
                },
                Load {
                    weight: w1,
                    com: (0.5, 0.5),
                    extent: rect(0.0, 1.0),
                    ground: None,
                    ground_studs: vec![],
                    z: 1,
                },
            ],
            contacts: vec![super::super::model::Contact {
                below: 0,
                above: 1,
                face: Some(rect(0.0, 1.0)),
                studs: vec![(0.5, 0.5)],
            }],
            under: vec![vec![], vec![0]],
            stop: None,
            progress: None,
        }
    }

    /// The piece alone tips; its proof is kept, and carried to the step
    /// that adds the counterweight only where the program also fails
    /// there: a moment past the edge of 0.1 fails, one of 2e-3 (held by a
    /// hand of less than the program's tolerance, a thousandth of the
    /// weight, at the far corner) the program lets stand, and so must the
    /// proof (found by a review: without the hand's work it carried that
    /// step as failing).
    #[test]
    fn a_failure_is_carried_only_where_the_program_fails_too() {
        use super::super::model::{solve_until, First};
        let params = Params::default();
        for (moment, fails) in [(0.1, true), (2e-3, false)] {
            let s = tipping((0.5 - moment) / 1.5);
            let mut cert = Certifier::new(&s, &params);
            cert.place(0);
            let (job, new) = cert.groups_with(&[0]).remove(0);
            assert!(matches!(cert.certify(&job, &new), Verdict::Fails));
            cert.place(1);
            let (job, new) = cert.groups_with(&[1]).remove(0);
            assert_eq!(job.pieces, [0, 1]);
            let carried = cert.still_fails(&job, &new);
            let contacts: Vec<_> = s.contacts.iter().collect();
            let program = solve_until(&s, &[0, 1], &contacts, &params, First::Least, None)
                .unwrap()
                .stress
                .iter()
                .any(PieceStress::fails);
            assert_eq!((carried, program), (fails, fails), "moment {moment}");
        }
    }

    #[test]
    fn a_new_pieces_way_down_follows_its_plumb_line() {
        use crate::assembly::{Assembly, Placement};
        use crate::catalog::{Color, PartKind};
        use crate::geom::{Cell, Rot};
        let at = |id: &str, x, z| {
            Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0)
        };
        // Two stacks of 1 x 2 bricks, at x 0 and x 4, bridged by a 1 x 6,
        // and a 1 x 2 on the bridge over the first stack. Lowest first,
        // the way goes down the stack placed first, the far one; the
        // plumb line of the new piece is over the near one.
        let order = [
            at("3004", 0, 0),
            at("3004", 4, 0),
            at("3004", 4, 1),
            at("3004", 0, 1),
            at("3009", 0, 2),
            at("3004", 0, 3),
        ];
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let params = Params::default();
        let s = Structure::new(&asm, &params);
        let mut cert = Certifier::new(&s, &params);
        cert.place_to(order.len());
        assert_eq!(cert.way_down(5, true), vec![0, 3, 4, 5]);
        assert_eq!(cert.way_down(5, false), vec![1, 2, 4, 5]);
        // Scratch marks are left clean.
        assert!(cert.local.iter().all(|&l| l == u32::MAX));
    }

    #[test]
    fn pushes_alone_carry_a_bridge_down_but_not_an_overhang() {
        use crate::assembly::{Assembly, Placement};
        use crate::catalog::{Color, PartKind};
        use crate::geom::{Cell, Rot};
        let at = |id: &str, x, z| {
            Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0)
        };
        let params = Params::default();
        // A 1 x 6 over two 1 x 2 stacks at its ends: its centre of mass
        // lies between the faces it rests on, on no one of them.
        let order = [at("3004", 0, 0), at("3004", 4, 0), at("3009", 0, 1)];
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let s = Structure::new(&asm, &params);
        let mut cert = Certifier::new(&s, &params);
        cert.place_to(order.len());
        assert!(cert.spread_down(&[0, 1, 2], true).is_none());
        assert!(cert.spread_down(&[0, 1, 2], false).is_some());
        let mut vars = Vec::new();
        assert!((0..order.len()).all(|p| cert.balanced(p, &mut vars)));
        assert!(cert.f.iter().all(|&f| f >= 0.0));
        let (_, bridge) = s.weight(2);
        let under = |k: usize| cert.f[cert.coff[k]..cert.coff[k] + 4].iter().sum::<f64>();
        let faces: Vec<f64> = s.under[2].iter().map(|&k| under(k)).collect();
        assert_eq!(faces.len(), 2);
        // The bridge's weight shared by its two ends, no clutch used.
        assert!(
            (faces[0] - faces[1]).abs() < 1e-12 && faces[0] > 0.0,
            "{faces:?}"
        );
        assert_eq!(bridge, (3.0, 0.5));
        let job = Job {
            pieces: vec![0, 1, 2],
            contacts: (0..s.contacts.len()).collect(),
            grounded: true,
        };
        assert!(cert.stress(&job).iter().all(|p| p.usage == 0.0));
        // A 1 x 6 hanging past the 1 x 4 it is clutched to: only a pull at
        // its studs holds it, so pushes alone do not, and nothing changes.
        let asm = counterweighted();
        let s = Structure::new(&asm, &params);
        let mut cert = Certifier::new(&s, &params);
        cert.place_to(asm.pieces.len());
        assert!(cert.spread_down(&[0, 1, 2], false).is_none());
        assert!(cert.f.iter().all(|&f| f == 0.0));
        // Its base and counterweight alone rest on pushes.
        assert!(cert.spread_down(&[0, 1], true).is_some());
        assert!([0, 1].iter().all(|&p| cert.balanced(p, &mut vars)));
    }

    /// An answer off its program by a thousandth (as a program stopped
    /// early leaves it: residuals in every equation, some forces past a
    /// bound) is settled to balance every piece within its bounds, and
    /// the clutch of the counterweighted build is still used.
    #[test]
    fn an_early_answer_is_settled_to_balance_every_piece() {
        let params = Params::default();
        let asm = counterweighted();
        let s = Structure::new(&asm, &params);
        let mut cert = Certifier::new(&s, &params);
        cert.place_to(asm.pieces.len());
        let (job, _) = cert.groups_with(&[0, 1, 2]).remove(0);
        for (i, &p) in job.pieces.iter().enumerate() {
            cert.local[p] = i as u32;
        }
        let Found::Change(vars, exact, false) = cert.solve_region(&job.pieces, 0.0) else {
            panic!("the counterweighted build has an equilibrium");
        };
        let program = cert.program(&job.pieces);
        let off: Vec<f64> = exact
            .iter()
            .enumerate()
            .map(|(j, x)| x + 1e-3 * ((j as f64) * 1.7).sin())
            .collect();
        let eq = program.eq;
        let settled = cert.settle(&program.vars, &off, &program.b[..eq], &program.a);
        let mut vars_of = Vec::new();
        let unbalanced = |c: &Certifier, vars_of: &mut Vec<Var>| {
            job.pieces
                .iter()
                .filter(|&&p| !c.balanced(p, vars_of))
                .count()
        };
        for (v, d) in vars.iter().zip(&off) {
            cert.f[v.at] += d;
        }
        assert!(unbalanced(&cert, &mut vars_of) > 0, "the answer is off");
        for (v, (d, e)) in vars.iter().zip(off.iter().zip(&settled)) {
            cert.f[v.at] += e - d;
        }
        assert_eq!(unbalanced(&cert, &mut vars_of), 0);
        for v in &vars {
            let f = cert.f[v.at];
            assert!(f >= 0.0 && (!v.tension || f <= CAP), "{f}");
        }
        let used = vars.iter().filter(|v| v.tension).map(|v| cert.f[v.at]);
        assert!(used.fold(0.0, f64::max) > 0.0);
    }

    #[test]
    fn a_regions_program_past_the_deadline_gives_no_answer() {
        // In time (or with no deadline), the clutch is found.
        let later = std::time::Instant::now() + std::time::Duration::from_secs(3600);
        for deadline in [None, Some(later)] {
            let Verdict::Stands(stress) = verdict(deadline) else {
                panic!("the counterweighted build stands");
            };
            assert!(stress.iter().any(|p| p.usage > 0.0), "{stress:?}");
        }
        // Past it, no program runs: neither stands nor fails is said.
        assert!(matches!(
            verdict(Some(std::time::Instant::now())),
            Verdict::Unknown
        ));
    }
}
