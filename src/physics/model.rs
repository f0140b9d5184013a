//! The force model: contacts between pieces, and one linear program per
//! connected group of pieces, solved with Clarabel.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use crate::assembly::verify::stacked_pairs;
use crate::assembly::Assembly;
use crate::geom::{Body, CellBox};

use super::{Ground, Params, PhysicsError, PieceStress};

/// Cost of one clutch capacity's worth of "hand" force (force units are
/// the clutch capacity of a stud): so high that the solver only reaches
/// for a hand when no real force can hold the piece.
const HAND_COST: f64 = 1e4;

/// Cost of a unit of stud tension, so that the solver does not pull and
/// push against itself where it need not.
const TENSION_COST: f64 = 1e-3;

/// Weight of the quadratic term `SPREAD / 2 * sum_j m_j^2` on the joints'
/// usages: it makes the cost strictly convex in the usages, so that every
/// joint's usage has one answer (the linear program's usages are not
/// unique where a load can be shared among joints in many ways at the same
/// total, and an interior-point solver's answer then depends on its path
/// and tolerance). It also spreads a shared load over the joints that can
/// take it, as clutch does, rather than loading one joint to spare another.
const SPREAD: f64 = 1.0;

/// How a program is solved: the weight of its quadratic term, the
/// solver's tolerance and whether it refines each Newton step. The
/// answers are the program's, whatever the method ([`Method::DEFAULT`]);
/// the others are for tests that show it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Method {
    /// [`SPREAD`]; 0 for the bare linear program.
    pub spread: f64,
    /// Clarabel's feasibility and gap tolerances.
    pub tolerance: f64,
    /// Clarabel's iterative refinement.
    pub refine: bool,
    /// Whether a hand may hold a piece (see [`HAND_COST`]); without,
    /// a group that needs one has no answer.
    pub hands: bool,
    /// Past this, the solver stops at its next iteration (no answer).
    pub until: Option<std::time::Instant>,
}

impl Method {
    pub const DEFAULT: Method = Method {
        spread: SPREAD,
        tolerance: 1e-8,
        // Refining each Newton step's linear solve took a third of the
        // time (its triangular solves and products); without it the
        // solver still stops only at its full tolerances on the true
        // residuals. On every step of a bunny at 32 studs: 1.4 times
        // faster, the same verdicts, every usage within 7e-4 of the
        // refined answer's (of the linear program, whose usages are not
        // unique).
        refine: false,
        hands: true,
        until: None,
    };
}

/// A horizontal rectangle in stud units: `[x0, x1] x [y0, y1]`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    fn of(b: &CellBox) -> Rect {
        Rect {
            x0: f64::from(b.min.x),
            y0: f64::from(b.min.y),
            x1: f64::from(b.min.x + b.sx),
            y1: f64::from(b.min.y + b.sy),
        }
    }

    pub fn corners(&self) -> [(f64, f64); 4] {
        [
            (self.x0, self.y0),
            (self.x1, self.y0),
            (self.x0, self.y1),
            (self.x1, self.y1),
        ]
    }
}

/// The footprint rectangle where two one-layer boxes' footprints overlap.
fn overlap(a: &CellBox, b: &CellBox) -> Option<CellBox> {
    let x0 = a.min.x.max(b.min.x);
    let y0 = a.min.y.max(b.min.y);
    let x1 = (a.min.x + a.sx).min(b.min.x + b.sx);
    let y1 = (a.min.y + a.sy).min(b.min.y + b.sy);
    (x0 < x1 && y0 < y1).then(|| CellBox {
        min: crate::geom::Cell::new(x0, y0, a.min.z),
        sx: x1 - x0,
        sy: y1 - y0,
        sz: 1,
    })
}

/// Where two pieces touch: `above` rests on `below`.
#[derive(Debug, Clone)]
pub(super) struct Contact {
    pub below: usize,
    pub above: usize,
    /// Where the faces press on each other (compression at its corners).
    pub face: Option<Rect>,
    /// The studs of `below` in `above`'s tubes, as cell centres.
    pub studs: Vec<(f64, f64)>,
}

/// One piece's load and its support by the ground.
#[derive(Debug, Clone)]
pub(super) struct Load {
    /// Weight in clutch capacities of a stud.
    pub weight: f64,
    /// Centre of mass, in studs.
    pub com: (f64, f64),
    /// The piece's bounding footprint (where a hand may hold it).
    pub extent: Rect,
    /// Its bottom face on the ground, if it stands on it.
    pub ground: Option<Rect>,
    /// Its tubes on a baseplate's studs ([`Ground::Baseplate`] only).
    pub ground_studs: Vec<(f64, f64)>,
    /// The layer of its bottom.
    pub z: i32,
}

/// The assembly seen as loads and contacts, built once.
#[derive(Debug, Clone)]
pub(super) struct Structure {
    pub loads: Vec<Load>,
    /// Sorted by the later piece (`max(below, above)`), then by the pair.
    pub contacts: Vec<Contact>,
    /// Per piece, the contacts (indices) with a face under it.
    pub under: Vec<Vec<usize>>,
    /// Once set, the solver stops at its next iteration (the answer is
    /// no longer wanted: see [`Pending`](super::Pending)).
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Where the solver says how far it is, with `stop`: the iterations
    /// of the program it is on (see [`Pending`](super::Pending)).
    pub progress: Option<std::sync::Arc<Progress>>,
}

/// How far the programs of a [`Structure`] went: iterations in all, and
/// of the one being solved (shared with whoever waits for them); and
/// whether a group's program within capacity was proved to have no
/// answer (the structure fails, before the program of least usage says
/// what fails in it; a group whose least usage lies within a millionth
/// under a stud's capacity may still be found standing by that program,
/// so this steers only what may be given up, never a verdict).
#[derive(Debug, Default)]
pub struct Progress {
    pub total: std::sync::atomic::AtomicU32,
    pub current: std::sync::atomic::AtomicU32,
    pub fails: std::sync::atomic::AtomicBool,
}

impl Structure {
    pub fn new(asm: &Assembly, params: &Params) -> Structure {
        let bodies: Vec<Body> = asm
            .pieces
            .iter()
            .map(|p| p.placement.body(asm.layer_ldu))
            .collect();
        let loads = asm
            .pieces
            .iter()
            .zip(&bodies)
            .map(|(p, b)| load(b, p.placement.part.spec().mass_g, params))
            .collect();
        let mut contacts: Vec<Contact> = stacked_pairs(&bodies)
            .into_iter()
            .filter_map(|(below, above)| contact(&bodies, below, above))
            .collect();
        contacts.sort_by_key(|c| (c.below.max(c.above), c.below, c.above));
        let mut under = vec![Vec::new(); asm.pieces.len()];
        for (k, c) in contacts.iter().enumerate() {
            if c.face.is_some() {
                under[c.above].push(k);
            }
        }
        Structure {
            loads,
            contacts,
            under,
            stop: None,
            progress: None,
        }
    }

    /// Whether the piece rests on the ground.
    pub fn grounded(&self, piece: usize) -> bool {
        self.loads[piece].ground.is_some()
    }

    /// The piece's weight (in clutch capacities) and centre of mass.
    pub fn weight(&self, piece: usize) -> (f64, (f64, f64)) {
        (self.loads[piece].weight, self.loads[piece].com)
    }

    /// The layer of the piece's bottom.
    pub fn bottom(&self, piece: usize) -> i32 {
        self.loads[piece].z
    }

    /// Where `piece` can push down in compression on the pieces `placed`
    /// accepts: each corner of a face under it, with the piece below
    /// (`None` for the ground), a face's four corners in a row.
    pub fn supports(
        &self,
        piece: usize,
        placed: impl Fn(usize) -> bool,
    ) -> Vec<(Option<usize>, (f64, f64))> {
        let mut out = Vec::new();
        for &k in &self.under[piece] {
            let c = &self.contacts[k];
            if let (true, Some(face)) = (placed(c.below), c.face) {
                out.extend(face.corners().map(|at| (Some(c.below), at)));
            }
        }
        if let Some(g) = self.loads[piece].ground {
            out.extend(g.corners().map(|at| (None, at)));
        }
        out
    }
}

fn load(b: &Body, mass_g: f32, params: &Params) -> Load {
    let (mut v, mut mx, mut my) = (0.0, 0.0, 0.0);
    for bx in b.boxes() {
        let vol = f64::from(bx.volume());
        let r = Rect::of(bx);
        v += vol;
        mx += vol * (r.x0 + r.x1) / 2.0;
        my += vol * (r.y0 + r.y1) / 2.0;
    }
    let on_ground = b.bbox.min.z == 0;
    let bottom = b.boxes()[0];
    let ground_studs = if on_ground && params.ground == Ground::Baseplate {
        b.tubes.cells().map(centre).collect()
    } else {
        Vec::new()
    };
    Load {
        weight: f64::from(mass_g) / 1000.0 * params.gravity / params.clutch_n,
        com: (mx / v, my / v),
        extent: Rect::of(&b.bbox),
        ground: on_ground.then(|| Rect::of(&bottom)),
        ground_studs,
        z: b.bbox.min.z,
    }
}

fn centre(c: crate::geom::Cell) -> (f64, f64) {
    (f64::from(c.x) + 0.5, f64::from(c.y) + 0.5)
}

fn contact(bodies: &[Body], below: usize, above: usize) -> Option<Contact> {
    let (a, b) = (&bodies[below], &bodies[above]);
    let top = a.boxes().last().copied().unwrap_or(a.bbox);
    let bottom = b.boxes()[0];
    let face = if top.max_excl().z == bottom.min.z {
        overlap(&top.layer_above(), &bottom).map(|r| Rect::of(&r))
    } else {
        None
    };
    let studs: Vec<(f64, f64)> = if a.holds(b) {
        overlap(&a.over_studs(), &b.tubes)
            .map(|r| r.cells().map(centre).collect())
            .unwrap_or_default()
    } else {
        Vec::new()
    };
    (face.is_some() || !studs.is_empty()).then_some(Contact {
        below,
        above,
        face,
        studs,
    })
}

/// A linear program under construction, one column at a time.
struct Lp {
    /// Column pointers, row indices and values of the constraint matrix.
    colptr: Vec<usize>,
    rowval: Vec<usize>,
    nzval: Vec<f64>,
    cost: Vec<f64>,
    /// First row of the `x >= 0` block; row `nonneg + j` bounds column `j`.
    nonneg: usize,
    /// Next free row of the `t - m <= 0` block.
    next_cap: usize,
    entries: Vec<(usize, f64)>,
}

impl Lp {
    fn column(&mut self, cost: f64, entries: &[(usize, f64)]) -> usize {
        let j = self.cost.len();
        self.entries.clear();
        self.entries.extend_from_slice(entries);
        self.entries.push((self.nonneg + j, -1.0));
        self.entries.sort_by_key(|e| e.0);
        for &(r, v) in &self.entries {
            self.rowval.push(r);
            self.nzval.push(v);
        }
        self.colptr.push(self.rowval.len());
        self.cost.push(cost);
        j
    }
}

/// The three equilibrium rows of a piece: vertical force, then the
/// moments about the axes through its centre of mass, for an upward force
/// `f` at `(x, y)`.
fn rows(local: usize, com: (f64, f64), (x, y): (f64, f64), f: f64) -> [(usize, f64); 3] {
    [
        (3 * local, f),
        (3 * local + 1, f * (x - com.0)),
        (3 * local + 2, f * (y - com.1)),
    ]
}

/// The solved forces of one group of pieces.
pub(super) struct Solved {
    /// Per piece of the group, in the group's order.
    pub stress: Vec<PieceStress>,
    /// Per prop of [`Props`], the force it carries.
    pub props: Vec<f64>,
}

/// An upward force a support column could give: under `piece` at `at`,
/// pushing down on `lands_on` (or on the ground).
#[derive(Debug, Clone, Copy)]
pub(super) struct Prop {
    pub piece: usize,
    pub at: (f64, f64),
    pub lands_on: Option<usize>,
    /// Cost of a unit of force.
    pub cost: f64,
}

/// Props the program may use, and the usage no joint may pass.
pub(super) struct Props<'a> {
    pub props: &'a [Prop],
    pub cap: f64,
}

/// The quadratic part of the program's cost: `spread` on the diagonal at
/// each joint's usage column (the `joints`' last entry, increasing), zero
/// elsewhere; upper triangular, as Clarabel takes it.
fn spread(cols: usize, joints: &[(usize, Option<usize>, usize)], spread: f64) -> CscMatrix<f64> {
    if spread == 0.0 {
        return CscMatrix::zeros((cols, cols));
    }
    let mut colptr = Vec::with_capacity(cols + 1);
    let mut rowval = Vec::with_capacity(joints.len());
    let mut nzval = Vec::with_capacity(joints.len());
    colptr.push(0);
    let mut next = joints.iter().map(|j| j.2).peekable();
    for j in 0..cols {
        if next.next_if_eq(&j).is_some() {
            rowval.push(j);
            nzval.push(spread);
        }
        colptr.push(rowval.len());
    }
    debug_assert!(next.peek().is_none(), "usage columns in order");
    CscMatrix::new(cols, cols, colptr, rowval, nzval)
}

/// The most a joint carries in the program held within capacity: just
/// under a stud's capacity (a usage of 1 breaks the joint).
pub(super) const CAP: f64 = 1.0 - 1e-6;

/// Whether `s`'s programs were told to stop (see [`Structure::stop`]).
fn stopped(s: &Structure) -> bool {
    s.stop
        .as_ref()
        .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
}

/// Whether `deadline` has passed.
pub(super) fn past(deadline: Option<std::time::Instant>) -> bool {
    deadline.is_some_and(|d| std::time::Instant::now() >= d)
}

/// Which of [`solve_until`]'s two programs is solved first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum First {
    /// Within capacity, no hand: for a group expected to stand (a
    /// finished model), which it settles in one program.
    Within,
    /// The least usage: for a group expected to fail (no certificate was
    /// found for it), whose answer names what fails.
    Least,
    /// Within capacity alone, for the verdict: a group with no
    /// equilibrium within capacity is given as falling whole, what fails
    /// in it not named (the second program, which names it, not solved).
    Verdict,
}

/// Solves the group `pieces` (sorted) with the `contacts` among them.
///
/// The group stands when its pieces have an equilibrium with every joint
/// within its capacity ([`CAP`]) and no hand (the safe theorem): the
/// program held so has an answer, and its least usage within capacity is
/// the group's stress (unique: see [`SPREAD`]). Where it has none, the
/// program of least usage, with hands, names the joints past their
/// capacity and the pieces that fall. That program alone is not a test:
/// its least usage may overload a joint where another equilibrium holds
/// every joint within capacity (the sum it minimises trades one joint's
/// excess for less at others); where it holds every joint within
/// capacity, its answer is the other program's.
///
/// `first` says which program is tried first: the one within capacity
/// when the group is expected to stand (then one program; the second
/// only if that has no answer), the least usage when it is expected to
/// fail (then one program; the second only if that answer breaks a joint
/// and needs no hand). The program within capacity has no hands'
/// columns, so it is smaller and better scaled: the shored bunny at 72
/// studs (4,998 pieces) 82 iterations and 53 s, where the least usage's
/// took 192 iterations and 129 s and then needed the other (it broke a
/// joint); the bunny at 64 16.2 s where the two took 18.3 and 19.0 s.
///
/// Its programs stop at `until`: past it, a program not solved gives
/// [`PhysicsError::Solver`].
pub(super) fn solve_until(
    s: &Structure,
    pieces: &[usize],
    contacts: &[&Contact],
    params: &Params,
    first: First,
    until: Option<std::time::Instant>,
) -> Result<Solved, PhysicsError> {
    let method = Method {
        until,
        ..Method::DEFAULT
    };
    let late = || stopped(s) || past(until);
    let within = || {
        let held = Props {
            props: &[],
            cap: CAP,
        };
        let bare = Method {
            hands: false,
            ..method
        };
        match solve_by(s, pieces, contacts, params, Some(&held), bare) {
            Ok(held) if !held.stress.iter().any(PieceStress::fails) => Ok(Some(held)),
            // Stopped (its answer no longer wanted): so would the other.
            Err(e @ PhysicsError::Solver { .. }) if late() => Err(e),
            // No answer within capacity (or the solver's trouble): the
            // other program says. The solver's proof that there is none
            // is told at once (see [`Progress::fails`]).
            Err(PhysicsError::Solver { status, .. }) if status == "PrimalInfeasible" => {
                if let Some(p) = &s.progress {
                    p.fails.store(true, std::sync::atomic::Ordering::Relaxed);
                }
                Ok(None)
            }
            Ok(_) | Err(PhysicsError::Solver { .. }) => Ok(None),
            Err(e) => Err(e),
        }
    };
    if first != First::Least {
        if let Some(held) = within()? {
            return Ok(held);
        }
        if first == First::Verdict {
            return Ok(Solved {
                stress: vec![PieceStress::falling(); pieces.len()],
                props: Vec::new(),
            });
        }
        return solve_by(s, pieces, contacts, params, None, method);
    }
    let least = solve_by(s, pieces, contacts, params, None, method)?;
    let breaks = least.stress.iter().any(|p| p.breaks);
    if !breaks || least.stress.iter().any(|p| p.falls) {
        return Ok(least);
    }
    Ok(within()?.unwrap_or(least))
}

/// [`solve_until`], where `props` may also push pieces up and every joint's
/// usage is held to at most `props.cap`: the props a structure needs to
/// hold with that margin (a hand still holds what no prop can).
pub(super) fn solve_propped(
    s: &Structure,
    pieces: &[usize],
    contacts: &[&Contact],
    params: &Params,
    extra: Option<&Props>,
    until: Option<std::time::Instant>,
) -> Result<Solved, PhysicsError> {
    let method = Method {
        until,
        ..Method::DEFAULT
    };
    solve_by(s, pieces, contacts, params, extra, method)
}

/// [`solve_propped`] by `method`.
pub(super) fn solve_by(
    s: &Structure,
    pieces: &[usize],
    contacts: &[&Contact],
    params: &Params,
    extra: Option<&Props>,
    method: Method,
) -> Result<Solved, PhysicsError> {
    let n = pieces.len();
    let local = |p: usize| pieces.binary_search(&p).expect("piece of the group");
    let props: &[Prop] = extra.map_or(&[], |e| e.props);
    // Count the columns and the capacity rows first: the x >= 0 rows
    // follow the equilibrium rows, the capacity rows follow those.
    let hand_cols = if method.hands { 4 } else { 0 };
    let mut cols = hand_cols * n + props.len();
    let mut caps = 0;
    let mut joint_count = 0;
    for c in contacts {
        cols += if c.face.is_some() { 4 } else { 0 };
        if !c.studs.is_empty() {
            cols += c.studs.len() + 1;
            caps += c.studs.len();
            joint_count += 1;
        }
    }
    for &p in pieces {
        let l = &s.loads[p];
        cols += if l.ground.is_some() { 4 } else { 0 };
        if !l.ground_studs.is_empty() {
            cols += l.ground_studs.len() + 1;
            caps += l.ground_studs.len();
            joint_count += 1;
        }
    }
    // With props, a row `m_j <= cap` per joint follows the capacity rows.
    let limits = if extra.is_some() { joint_count } else { 0 };
    let mut next_limit = 3 * n + cols + caps;
    let eq = 3 * n;
    let mut lp = Lp {
        colptr: vec![0],
        rowval: Vec::new(),
        nzval: Vec::new(),
        cost: Vec::with_capacity(cols),
        nonneg: eq,
        next_cap: eq + cols,
        entries: Vec::new(),
    };
    // Joints: (first piece, second piece or none for the ground, column of m).
    let mut joints: Vec<(usize, Option<usize>, usize)> = Vec::new();
    let mut hands = Vec::with_capacity(n);
    for (i, &p) in pieces.iter().enumerate() {
        let l = &s.loads[p];
        let first = lp.cost.len();
        if method.hands {
            for corner in l.extent.corners() {
                lp.column(HAND_COST, &rows(i, l.com, corner, 1.0));
            }
        }
        hands.push(first);
        if let Some(g) = l.ground {
            for corner in g.corners() {
                lp.column(0.0, &rows(i, l.com, corner, 1.0));
            }
        }
        if !l.ground_studs.is_empty() {
            let cap0 = lp.next_cap;
            lp.next_cap += l.ground_studs.len();
            for (k, &at) in l.ground_studs.iter().enumerate() {
                let mut e = rows(i, l.com, at, -1.0).to_vec();
                e.push((cap0 + k, 1.0));
                lp.column(TENSION_COST, &e);
            }
            let mut caps_rows: Vec<(usize, f64)> = (0..l.ground_studs.len())
                .map(|k| (cap0 + k, -1.0))
                .collect();
            if extra.is_some() {
                caps_rows.push((next_limit, 1.0));
                next_limit += 1;
            }
            let m = lp.column(1.0, &caps_rows);
            joints.push((i, None, m));
        }
    }
    for c in contacts {
        let (a, b) = (local(c.below), local(c.above));
        let (la, lb) = (&s.loads[c.below], &s.loads[c.above]);
        if let Some(face) = c.face {
            for at in face.corners() {
                let mut e = rows(b, lb.com, at, 1.0).to_vec();
                e.extend(rows(a, la.com, at, -1.0));
                lp.column(0.0, &e);
            }
        }
        if !c.studs.is_empty() {
            let cap0 = lp.next_cap;
            lp.next_cap += c.studs.len();
            for (k, &at) in c.studs.iter().enumerate() {
                let mut e = rows(b, lb.com, at, -1.0).to_vec();
                e.extend(rows(a, la.com, at, 1.0));
                e.push((cap0 + k, 1.0));
                lp.column(TENSION_COST, &e);
            }
            let mut caps_rows: Vec<(usize, f64)> =
                (0..c.studs.len()).map(|k| (cap0 + k, -1.0)).collect();
            if extra.is_some() {
                caps_rows.push((next_limit, 1.0));
                next_limit += 1;
            }
            let m = lp.column(1.0, &caps_rows);
            joints.push((a, Some(b), m));
        }
    }
    let first_prop = lp.cost.len();
    for prop in props {
        let mut e = rows(local(prop.piece), s.loads[prop.piece].com, prop.at, 1.0).to_vec();
        if let Some(q) = prop.lands_on {
            e.extend(rows(local(q), s.loads[q].com, prop.at, -1.0));
        }
        lp.column(prop.cost, &e);
    }
    debug_assert_eq!(lp.cost.len(), cols);
    debug_assert_eq!(lp.next_cap, eq + cols + caps);
    debug_assert_eq!(next_limit, eq + cols + caps + limits);
    let m_rows = eq + cols + caps + limits;
    let mut b = vec![0.0; m_rows];
    for (i, &p) in pieces.iter().enumerate() {
        b[3 * i] = s.loads[p].weight;
    }
    if let Some(e) = extra {
        for r in &mut b[eq + cols + caps..] {
            *r = e.cap;
        }
    }
    let a = CscMatrix::new(m_rows, cols, lp.colptr, lp.rowval, lp.nzval);
    let pm = spread(cols, &joints, method.spread);
    let cones = [
        SupportedConeT::ZeroConeT(eq),
        SupportedConeT::NonnegativeConeT(cols + caps + limits),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_threads(1)
        .direct_solve_method("qdldl".to_string())
        .iterative_refinement_enable(method.refine)
        .tol_feas(method.tolerance)
        .tol_gap_abs(method.tolerance)
        .tol_gap_rel(method.tolerance)
        .build()
        .map_err(|e| PhysicsError::Bug(format!("solver settings: {e}")))?;
    let mut solver = DefaultSolver::new(&pm, &lp.cost, &a, &b, &cones, settings)
        .map_err(|e| PhysicsError::Bug(format!("solver setup: {e:?}")))?;
    if s.stop.is_some() || method.until.is_some() {
        let (stop, progress, until) = (s.stop.clone(), s.progress.clone(), method.until);
        solver.set_termination_callback(move |info| {
            use std::sync::atomic::Ordering::Relaxed;
            if let Some(p) = &progress {
                p.total.fetch_add(1, Relaxed);
                p.current.store(info.iterations, Relaxed);
            }
            stop.as_ref().is_some_and(|f| f.load(Relaxed)) || past(until)
        });
    }
    solver.solve();
    let status = solver.solution.status;
    if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
        return Err(PhysicsError::Solver {
            pieces: n,
            status: format!("{status:?}"),
        });
    }
    let x = &solver.solution.x;
    let mut stress: Vec<PieceStress> = pieces
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let hand: f64 = x[hands[i]..hands[i] + hand_cols].iter().sum();
            let weight = s.loads[p].weight;
            PieceStress {
                usage: 0.0,
                score: 1.0,
                falls: hand > params.fall_tolerance * weight,
                breaks: false,
            }
        })
        .collect();
    for &(a, b, m) in &joints {
        let u = x[m].max(0.0);
        for i in std::iter::once(a).chain(b) {
            stress[i].usage = stress[i].usage.max(u);
        }
    }
    for st in &mut stress {
        st.finish();
    }
    let props = x[first_prop..first_prop + props.len()]
        .iter()
        .map(|f| f.max(0.0))
        .collect();
    Ok(Solved { stress, props })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture_build(name: &str, studs: u32) -> Assembly {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures")
            .join(name);
        crate::pipeline::bricks_by_course(&path, studs).expect("the fixture builds")
    }

    fn usages(s: &Structure, n: usize, params: &Params, method: Method) -> Vec<f64> {
        let pieces: Vec<usize> = (0..n).collect();
        let contacts: Vec<&Contact> = s.contacts.iter().collect();
        solve_by(s, &pieces, &contacts, params, None, method)
            .unwrap()
            .stress
            .iter()
            .map(|p| p.usage)
            .collect()
    }

    /// The largest difference between two lists of usages.
    fn apart(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    /// A program whose deadline has passed stops at once and gives no
    /// answer; with none, or one to come, it is solved.
    #[test]
    fn a_program_past_its_deadline_gives_no_answer() {
        let params = Params::default();
        let asm = crate::physics::fixtures::counterweighted();
        let s = Structure::new(&asm, &params);
        let pieces: Vec<usize> = (0..asm.pieces.len()).collect();
        let contacts: Vec<&Contact> = s.contacts.iter().collect();
        let now = std::time::Instant::now();
        for first in [First::Within, First::Least] {
            let past = solve_until(&s, &pieces, &contacts, &params, first, Some(now));
            assert!(
                matches!(past, Err(PhysicsError::Solver { .. })),
                "{first:?}"
            );
            let later = now + std::time::Duration::from_secs(3600);
            for until in [None, Some(later)] {
                let solved = solve_until(&s, &pieces, &contacts, &params, first, until).unwrap();
                assert!(!solved.stress.iter().any(PieceStress::fails));
            }
        }
    }

    /// The verdict alone: where the model stands, the analysis
    /// [`crate::physics::analyze`] gives; where it does not, none, with
    /// one program (the counterweighted overhang without its
    /// counterweight breaks off).
    #[test]
    fn the_verdict_alone_is_the_analysis_where_it_stands_and_none_else() {
        let params = Params::default();
        let asm = crate::physics::fixtures::counterweighted();
        let whole = crate::physics::analyze(&asm, &params).unwrap();
        assert!(whole.stands());
        let verdict = crate::physics::analyze_if_stands(&asm, &params)
            .unwrap()
            .expect("it stands");
        assert_eq!(verdict.pieces, whole.pieces);
        let bare = Assembly {
            pieces: vec![asm.pieces[0], asm.pieces[2]],
            layer_ldu: asm.layer_ldu,
        };
        assert!(!crate::physics::analyze(&bare, &params).unwrap().stands());
        assert!(crate::physics::analyze_if_stands(&bare, &params)
            .unwrap()
            .is_none());
    }

    /// The arch at 24 studs: its linear program shares loads among joints
    /// in more than one way at the same least total usage, and Clarabel's
    /// answer moves with its path. The program with the usages' squares
    /// has one answer, and the solver finds it however it is run.
    #[test]
    fn the_usages_are_the_programs_not_the_solvers() {
        let params = Params::default();
        let asm = fixture_build("arch.obj", 24);
        let s = Structure::new(&asm, &params);
        let n = asm.pieces.len();
        let by = |spread, tolerance, refine| {
            let method = Method {
                spread,
                tolerance,
                refine,
                hands: true,
                until: None,
            };
            usages(&s, n, &params, method)
        };
        let ours = by(SPREAD, 1e-8, false);
        assert_eq!(ours, usages(&s, n, &params, Method::DEFAULT));
        // Each step's linear solve refined, or a tolerance of 1e-10:
        // within 1e-7 (measured 5.4e-9 and 5.9e-8).
        assert!(apart(&ours, &by(SPREAD, 1e-8, true)) < 1e-7);
        assert!(apart(&ours, &by(SPREAD, 1e-10, true)) < 1e-7);
        // The bare linear program, run the same ways: 5.7e-5 apart.
        let lp = by(0.0, 1e-8, false);
        assert!(apart(&lp, &by(0.0, 1e-8, true)) > 1e-5);
        assert!(apart(&lp, &by(0.0, 1e-10, true)) > 1e-5);
        // Where the two programs differ, ours spreads a shared load: its
        // highest usage is lower (0.0024 against 0.0026), and no piece's
        // usage is more than 5e-4 from the linear program's (3.6e-4).
        let max = |u: &[f64]| u.iter().copied().fold(0.0, f64::max);
        assert!(max(&ours) <= max(&lp) + 1e-9, "{} {}", max(&ours), max(&lp));
        assert!(apart(&ours, &lp) < 5e-4, "{}", apart(&ours, &lp));
    }

    /// Either program first, one answer: on a build that stands (the arch
    /// at 24 studs, one program within capacity or of least usage, whose
    /// answers are the same optimum) the usages agree within 1e-6; on an
    /// overhang that tips its base over (a 1x6 clutched by one stud to
    /// the end of a 1x4), the program within capacity has none, and both
    /// give the least usage's answer: it falls.
    #[test]
    fn a_group_solved_within_capacity_first_or_least_usage_first_has_one_answer() {
        let params = Params::default();
        let both = |asm: &Assembly| {
            let s = Structure::new(asm, &params);
            let pieces: Vec<usize> = (0..asm.pieces.len()).collect();
            let contacts: Vec<&Contact> = s.contacts.iter().collect();
            let by = |first| {
                solve_until(&s, &pieces, &contacts, &params, first, None)
                    .unwrap()
                    .stress
            };
            (by(First::Within), by(First::Least))
        };
        let usage = |st: &[PieceStress]| st.iter().map(|p| p.usage).collect::<Vec<_>>();
        let (within, least) = both(&fixture_build("arch.obj", 24));
        assert!(!within.iter().any(PieceStress::fails));
        assert!(apart(&usage(&within), &usage(&least)) < 1e-6);
        let at = |id: &str, x, z| {
            crate::assembly::Placement::new(
                crate::catalog::PartKind::from_id(id).unwrap(),
                crate::geom::Cell::new(x, 0, z),
                crate::geom::Rot::R0,
            )
        };
        let overhang = Assembly::from_order(
            &[at("3010", 0, 0), at("3009", 3, 1)],
            24,
            crate::catalog::Color::RED,
        );
        let (within, least) = both(&overhang);
        assert!(within.iter().any(PieceStress::fails), "{within:?}");
        assert_eq!(within, least);
    }
}
