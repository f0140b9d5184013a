//! Support columns: what a build gets where no layout or order of its own
//! pieces holds it.
//!
//! Some shapes cannot stand on their own pieces: a head on a thin neck
//! whose weight is outside its footprint, a wing held by one course of
//! studs. Builders of display models prop such parts with columns of
//! plain bricks, often in a colour of their own. [`shore_up`] does the
//! same, guided by the force model:
//!
//! 1. every cell under a piece's bottom that is empty all the way down to
//!    the ground (or to the top of a piece built before it) is a
//!    **candidate column**; under a piece hung from one built before it
//!    (pressed on from below, as a table top's first course between its
//!    legs), only if the piece moves to stand on the column, first in the
//!    step of the piece it hung from, and only when the caller allows it
//!    (after every other repair) and no other candidate helps;
//! 2. one linear program (`model::solve_propped`) lets every candidate push its
//!    piece up, at a price per unit of force, while no stud joint may use
//!    more than [`TARGET`] of its clutch: the candidates it leans on are
//!    where support does the most good (a prop far out on an overhang
//!    needs less force than one near its root, so the price picks it);
//! 3. the columns carrying the most force become real pieces: bricks
//!    (topped with plates where the grid is a plate high) 2 x 2 where
//!    there is room, else 2 x 1, 1 x 2 or 1 x 1, added in steps of their
//!    own (at most [`STEP_PIECES`] pieces each) just before the piece they
//!    hold;
//! 4. the structure is analysed again, and the rounds repeat until it
//!    stands, or [`MAX_COLUMNS`] columns are in, or 12 rounds have run, or
//!    the deadline passes.
//!
//! Columns only fill cells no piece fills, so the model's own shape is
//! unchanged; the caller verifies the result (connection, placeability)
//! and checks every step again.

use std::collections::{HashMap, HashSet};

use serde::Serialize;

use super::model::{past, solve_propped, First, Prop, Props, Structure};
use super::{analyze_by, Params, PhysicsError};
use crate::assembly::verify::{verify, Failure};
use crate::assembly::{Assembly, Placed, Placement, Step, MAX_STEPS, STEP_MIN_PIECES, STEP_PIECES};
use crate::catalog::{Color, PartKind};
use crate::geom::{Body, Cell, Rot};

/// The share of a stud's clutch capacity no joint may use once propped:
/// a margin below breaking.
pub const TARGET: f64 = 0.9;

/// Columns a build gets at most; a build that needs more keeps what it has.
pub const MAX_COLUMNS: usize = 48;

/// Columns added in one round at most.
const PER_ROUND: usize = 6;

/// Plans a round may make at most, leaving out columns that cannot be put
/// in place.
const TRIES: usize = 4;

/// Rounds of planning and checking at most.
const ROUNDS: usize = 12;

/// Price of a unit of prop force (clutch units), and more per layer of
/// column: far below a hand's, far above a unit of clutch usage.
const PROP_COST: f64 = 10.0;
const PROP_COST_PER_LAYER: f64 = 0.5;

/// More per unit of prop force under a hung piece, which then moves (see
/// [`Candidate::before`]): a column where no piece moves is taken first.
const MOVE_COST: f64 = 30.0;

/// A prop weaker than this share of the strongest one in a round is left
/// for a later round.
const KEEP_SHARE: f64 = 0.25;

/// A support column.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Column {
    /// Stud column of its minimum corner.
    pub x: i32,
    /// Stud row of its minimum corner.
    pub y: i32,
    /// Its footprint in studs: 2 x 2 where there is room, else 2 x 1,
    /// 1 x 2 or 1 x 1.
    pub size: [i32; 2],
    /// Lowest layer it fills.
    pub bottom: i32,
    /// Highest layer it fills.
    pub top: i32,
    /// The step that adds it, or its first piece when it takes several
    /// (its own, just before the step of the piece it holds).
    pub step: u32,
    /// The step that adds its top piece: `step` unless the column is
    /// taller than a step holds.
    pub last_step: u32,
    /// Whether it stands on the ground (else on a piece).
    pub on_ground: bool,
    /// Pieces it is made of.
    pub pieces: usize,
}

/// A column that could go under a piece.
#[derive(Debug, Clone)]
struct Candidate {
    /// The piece held up.
    piece: usize,
    /// The cell under the piece where the column pushes it up.
    x: i32,
    y: i32,
    /// The column's footprint: minimum corner and size.
    foot: (i32, i32, i32, i32),
    bottom: i32,
    lands_on: Option<usize>,
    /// The piece the column goes in before: the piece held, or the piece
    /// built first over it when it was hung under that one (it then moves
    /// to stand on the column, before that piece, see [`insert`]).
    before: usize,
}

impl Candidate {
    /// Whether the piece held is hung under a piece built before it, and
    /// moves to stand on the column instead.
    fn moves(&self) -> bool {
        self.before != self.piece
    }

    /// Whether the column's footprint covers stud `(x, y)`.
    fn covers(&self, x: i32, y: i32) -> bool {
        let (x0, y0, sx, sy) = self.foot;
        x >= x0 && x < x0 + sx && y >= y0 && y < y0 + sy
    }

    /// The studs of its footprint.
    fn studs(&self) -> impl Iterator<Item = (i32, i32)> {
        let (x0, y0, sx, sy) = self.foot;
        (y0..y0 + sy).flat_map(move |y| (x0..x0 + sx).map(move |x| (x, y)))
    }

    /// Its key among excluded columns.
    fn key(&self) -> Footprint {
        let (x0, y0, sx, sy) = self.foot;
        (x0, y0, sx, sy, self.bottom)
    }
}

/// A column's footprint and bottom layer: `(x0, y0, sx, sy, bottom)`.
type Footprint = (i32, i32, i32, i32, i32);

/// What [`shore_up`] did.
#[derive(Debug, Clone)]
pub struct Shored {
    /// The assembly with its columns, steps renumbered.
    pub assembly: Assembly,
    /// The columns added, in build order.
    pub columns: Vec<Column>,
    /// The pieces the columns are made of.
    pub pieces: Vec<Placement>,
    /// The structure up to the step checked stands.
    pub stands: bool,
    /// Force analyses run.
    pub solves: usize,
}

/// What [`shore_up`] holds up: the structure built by the end of a step,
/// or the finished model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Upto {
    /// The finished model.
    Finished,
    /// The structure built by the end of this step.
    Step(u32),
    /// The structure built by the end of this step, which the caller's
    /// check found failing: the first round plans its columns at once,
    /// without a program of its own to say so again.
    Failing(u32),
}

/// Adds support columns until the structure built by the end of step
/// `upto` stands, or [`MAX_COLUMNS`]
/// (counting `already`) are in, or the deadline passes (a round that
/// would end past it, taking as long as the round before, does not
/// start, and a round's programs stop at it: the columns of the rounds
/// before are kept). Columns are made of pieces in `color`. With `moves`, a column
/// may go under a piece hung from one built before it, which moves to
/// stand on it (where no other column helps; see the module docs). `None`
/// when no column could be added.
pub fn shore_up(
    assembly: &Assembly,
    params: &Params,
    upto: Upto,
    already: usize,
    color: Color,
    deadline: Option<std::time::Instant>,
    moves: bool,
) -> Result<Option<Shored>, PhysicsError> {
    let mut asm = assembly.clone();
    // Whether the structure is known to fail (only before the first
    // round's columns), and the last step it holds.
    let (mut known_to_fail, mut upto) = match upto {
        Upto::Finished => (false, None),
        Upto::Step(s) => (false, Some(s)),
        Upto::Failing(s) => (true, Some(s)),
    };
    let mut columns: Vec<Column> = Vec::new();
    let mut pieces: Vec<Placement> = Vec::new();
    let mut solves = 0;
    let mut stands = false;
    let mut excluded: HashSet<Footprint> = HashSet::new();
    // The last round only checks the columns the one before added.
    // A round that would not end by the deadline (taking as long as the
    // one before) does not start.
    let mut last_round = std::time::Duration::ZERO;
    for round in 0..=ROUNDS {
        let begun = std::time::Instant::now();
        if deadline.is_some_and(|d| begun + last_round >= d) {
            break;
        }
        let end = match upto {
            Some(s) => asm.pieces.iter().take_while(|p| p.step.0 <= s).count(),
            None => asm.pieces.len(),
        };
        let prefix = Assembly {
            pieces: asm.pieces[..end].to_vec(),
            layer_ldu: asm.layer_ldu,
        };
        // Its programs, and the plan's, stop at the deadline: a round past
        // it ends the rounds with the columns found so far. The verdict
        // alone: what fails is the plan's program's to find.
        if !std::mem::take(&mut known_to_fail) {
            solves += 1;
            match analyze_by(&prefix, params, First::Verdict, deadline) {
                Ok(a) if a.stands() => {
                    stands = true;
                    break;
                }
                Ok(_) => {}
                Err(PhysicsError::Solver { .. }) if past(deadline) => break,
                Err(e) => return Err(e),
            }
        }
        let room = MAX_COLUMNS.saturating_sub(already + columns.len());
        if room == 0 || round == ROUNDS {
            break;
        }
        // Columns that cannot be put in place (built pieces enclose them,
        // or they would enclose a later piece) are planned again without.
        let mut found = None;
        for _ in 0..TRIES {
            let chosen = match plan(
                &asm,
                end,
                params,
                room.min(PER_ROUND),
                &excluded,
                moves,
                deadline,
            ) {
                Ok(chosen) => chosen,
                Err(PhysicsError::Solver { .. }) if past(deadline) => break,
                Err(e) => return Err(e),
            };
            solves += 1;
            if chosen.is_empty() {
                break;
            }
            let (next, added, placed) = insert(&asm, &chosen, color);
            let blocked = unplaceable(&next, &placed, &chosen);
            if blocked.is_empty() {
                found = Some((next, added, placed));
                break;
            }
            excluded.extend(blocked);
        }
        let Some((next, added, placed)) = found else {
            break;
        };
        if let Some(s) = upto.as_mut() {
            // Every column comes before the piece it holds, in the prefix.
            *s = next.pieces[end - 1 + placed.len()].step.0;
        }
        asm = next;
        columns.extend(added);
        pieces.extend(placed);
        last_round = begun.elapsed();
    }
    if columns.is_empty() {
        return Ok(None);
    }
    steps_of(&asm, &mut columns);
    Ok(Some(Shored {
        assembly: asm,
        columns,
        pieces,
        stands,
        solves,
    }))
}

/// The columns of `chosen` (as `(x, y, bottom)`) that make `asm` fail
/// the verifier's connection or placeability rules: those whose pieces
/// fail, and when a model piece fails instead, every column near it.
fn unplaceable(asm: &Assembly, placed: &[Placement], chosen: &[Candidate]) -> Vec<Footprint> {
    let column_pieces: HashSet<&Placement> = placed.iter().collect();
    // The column a piece of `asm` belongs to, if any.
    let column_of = |piece: usize| {
        let p = &asm.pieces[piece].placement;
        if !column_pieces.contains(p) {
            return None;
        }
        chosen
            .iter()
            .find(|c| c.covers(p.origin.x, p.origin.y) && c.bottom <= p.origin.z)
    };
    let mut out = Vec::new();
    let report = verify(asm, None);
    for f in &report.failures {
        match *f {
            Failure::Overlap { a, b, .. } => {
                out.extend([a, b].into_iter().filter_map(column_of).map(Candidate::key));
            }
            Failure::NotPlaceable { piece, .. }
            | Failure::Enclosed { piece, .. }
            | Failure::NotConnected { piece, .. } => {
                if let Some(c) = column_of(piece) {
                    out.push(c.key());
                    continue;
                }
                // A model piece the columns enclose: blame those beside it.
                let b = asm.pieces[piece].placement.body(asm.layer_ldu).bbox;
                out.extend(
                    chosen
                        .iter()
                        .filter(|c| {
                            c.studs().any(|(x, y)| {
                                x >= b.min.x - 1
                                    && x <= b.min.x + b.sx
                                    && y >= b.min.y - 1
                                    && y <= b.min.y + b.sy
                            })
                        })
                        .map(Candidate::key),
                );
            }
            _ => {}
        }
    }
    if out.is_empty() && !report.is_ok() {
        // Something else failed: none of this round's columns is safe.
        out.extend(chosen.iter().map(Candidate::key));
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Layers a piece `height_ldu` high fills in a grid of `layer_ldu`
/// layers (`None`: no whole number).
fn layers(layer_ldu: i32, height_ldu: i32) -> Option<i32> {
    (height_ldu % layer_ldu == 0).then_some(height_ldu / layer_ldu)
}

/// The pieces of footprint `sx` x `sy` that fill `h` layers, bottom up:
/// bricks, then plates for the rest, each with its turn and layers.
/// `None` when the grid's layers cannot be filled.
fn fill(layer_ldu: i32, h: i32, sx: i32, sy: i32) -> Option<Vec<(PartKind, Rot, i32)>> {
    let (brick, plate) = match (sx.max(sy), sx.min(sy)) {
        (1, 1) => ("3005", "3024"),
        (2, 1) => ("3004", "3023b"),
        (2, 2) => ("3003", "3022"),
        _ => return None,
    };
    let brick = PartKind::from_id(brick)?;
    let plate = PartKind::from_id(plate)?;
    let rot = if brick.spec().footprint(Rot::R0) == (sx, sy) {
        Rot::R0
    } else {
        Rot::R90
    };
    let lb = layers(layer_ldu, brick.spec().height_ldu())?;
    let (n, rest) = (h / lb, h % lb);
    let mut out: Vec<(PartKind, Rot, i32)> = (0..n).map(|_| (brick, rot, lb)).collect();
    if rest > 0 {
        let lp = layers(layer_ldu, plate.spec().height_ldu())?;
        if rest % lp != 0 {
            return None;
        }
        out.extend((0..rest / lp).map(|_| (plate, rot, lp)));
    }
    Some(out)
}

/// Footprints a column may take, widest first: a wider column stands
/// firmer and holds with more studs.
const SIZES: [(i32, i32); 4] = [(2, 2), (2, 1), (1, 2), (1, 1)];

/// Every candidate column under the first `end` pieces.
fn candidates(
    asm: &Assembly,
    bodies: &[Body],
    end: usize,
    excluded: &HashSet<Footprint>,
) -> Vec<Candidate> {
    let mut owner: HashMap<Cell, usize> = HashMap::new();
    // The verifier counts a piece's whole bounding box as taken (a slope's
    // open front included): so do the columns.
    for (i, b) in bodies.iter().enumerate() {
        for c in b.bbox.cells() {
            owner.insert(c, i);
        }
    }
    let ground = bodies.iter().map(|b| b.bbox.min.z).min().unwrap_or(0);
    // The first piece of each piece's step: a column must land on a piece
    // built before that step.
    let mut step_start = vec![0; asm.pieces.len()];
    for i in 1..asm.pieces.len() {
        step_start[i] = if asm.pieces[i].step == asm.pieces[i - 1].step {
            step_start[i - 1]
        } else {
            i
        };
    }
    let top = bodies
        .iter()
        .map(|b| b.bbox.max_excl().z)
        .max()
        .unwrap_or(0);
    // A piece hung under one built before it is pressed on from below: a
    // column under it would bar the way, unless the piece moves to stand
    // on the column before the first piece built over it (its hanger).
    let owned = &owner;
    let hanger: Vec<Option<usize>> = bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let z = b.bbox.min.z;
            b.bbox
                .cells()
                .filter(|c| c.z == z)
                .flat_map(|c| {
                    (b.bbox.max_excl().z..top)
                        .filter_map(move |zz| owned.get(&Cell::new(c.x, c.y, zz)).copied())
                })
                .filter(|&j| j < i)
                .min()
        })
        .collect();
    // Columns stay within the model's footprint box (and so within its
    // voxel grid).
    let (lo, hi) = bodies.iter().fold(
        ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN)),
        |((x0, y0), (x1, y1)), b| {
            let m = b.bbox.max_excl();
            (
                (x0.min(b.bbox.min.x), y0.min(b.bbox.min.y)),
                (x1.max(m.x), y1.max(m.y)),
            )
        },
    );
    let free = |x: i32, y: i32, z: i32| {
        x >= lo.0 && x < hi.0 && y >= lo.1 && y < hi.1 && !owner.contains_key(&Cell::new(x, y, z))
    };
    let mut out = Vec::new();
    for (i, b) in bodies.iter().enumerate().take(end) {
        let z = b.bbox.min.z;
        if z == ground {
            continue;
        }
        // The piece the column goes in before, and the first piece of its
        // step: the column lands on a piece built before that.
        let before = hanger[i].unwrap_or(i);
        let start = step_start[before];
        for c in b.tubes.cells() {
            let mut zb = z - 1;
            while zb >= ground && free(c.x, c.y, zb) {
                zb -= 1;
            }
            if zb == z - 1 {
                continue;
            }
            // What a stud of the footprint stands on: the ground, or the
            // stud of a piece built before this one's step.
            let base = |x: i32, y: i32| -> Option<Option<usize>> {
                if zb < ground {
                    return Some(None);
                }
                let q = *owner.get(&Cell::new(x, y, zb))?;
                (q < start && bodies[q].studs.contains(Cell::new(x, y, zb))).then_some(Some(q))
            };
            let Some(lands_on) = base(c.x, c.y) else {
                continue;
            };
            // The widest footprint around the cell whose every stud is free
            // from the base up to the piece's layer, stands on the same
            // base, and tops out under this piece, under nothing, or under
            // a later piece that is not hung.
            let fits = |x0: i32, y0: i32, sx: i32, sy: i32| {
                fill(asm.layer_ldu, z - 1 - zb, sx, sy).is_some()
                    && (y0..y0 + sy).all(|y| {
                        (x0..x0 + sx).all(|x| {
                            (zb + 1..z).all(|zz| free(x, y, zz))
                                && base(x, y).is_some_and(|q| q.is_some() == lands_on.is_some())
                                && {
                                    let over = owner.get(&Cell::new(x, y, z));
                                    // Under a piece that moves, wholly
                                    // under it: what is over the rest may
                                    // be built before the column.
                                    if before != i {
                                        over == Some(&i)
                                    } else {
                                        over.is_none_or(|&j| {
                                            j == i || (j >= step_start[i] && hanger[j].is_none())
                                        })
                                    }
                                }
                        })
                    })
            };
            let foot = SIZES.iter().find_map(|&(sx, sy)| {
                (0..sy)
                    .flat_map(|dy| (0..sx).map(move |dx| (c.x - dx, c.y - dy)))
                    .find(|&(x0, y0)| {
                        !excluded.contains(&(x0, y0, sx, sy, zb + 1)) && fits(x0, y0, sx, sy)
                    })
                    .map(|(x0, y0)| (x0, y0, sx, sy))
            });
            let Some(foot) = foot else {
                continue;
            };
            out.push(Candidate {
                piece: i,
                x: c.x,
                y: c.y,
                foot,
                bottom: zb + 1,
                lands_on,
                before,
            });
        }
    }
    out
}

/// The columns the structure of the first `end` pieces leans on most, at
/// most `max`, one a cell.
fn plan(
    asm: &Assembly,
    end: usize,
    params: &Params,
    max: usize,
    excluded: &HashSet<Footprint>,
    moves: bool,
    deadline: Option<std::time::Instant>,
) -> Result<Vec<Candidate>, PhysicsError> {
    let bodies: Vec<Body> = asm
        .pieces
        .iter()
        .map(|p| p.placement.body(asm.layer_ldu))
        .collect();
    let (mut moving, fixed): (Vec<Candidate>, Vec<Candidate>) =
        candidates(asm, &bodies, end, excluded)
            .into_iter()
            .partition(Candidate::moves);
    if !moves {
        moving.clear();
    }
    if fixed.is_empty() && moving.is_empty() {
        return Ok(Vec::new());
    }
    let prefix = Assembly {
        pieces: asm.pieces[..end].to_vec(),
        layer_ldu: asm.layer_ldu,
    };
    let s = Structure::new(&prefix, params);
    // The columns under pieces that stay where they are first; those
    // under hung pieces, which move, only where none of those helps (a
    // piece moved changes the steps around it).
    let chosen = choose(&s, &bodies, end, params, max, &fixed, deadline)?;
    if !chosen.is_empty() || moving.is_empty() {
        return Ok(chosen);
    }
    let all: Vec<Candidate> = fixed.into_iter().chain(moving).collect();
    choose(&s, &bodies, end, params, max, &all, deadline)
}

/// Of the candidate columns `all` under the structure `s` of the first
/// `end` pieces, the ones its propped program leans on most, at most
/// `max`, one a cell; none if it leans on none.
fn choose(
    s: &Structure,
    bodies: &[Body],
    end: usize,
    params: &Params,
    max: usize,
    all: &[Candidate],
    until: Option<std::time::Instant>,
) -> Result<Vec<Candidate>, PhysicsError> {
    if all.is_empty() {
        return Ok(Vec::new());
    }
    let props: Vec<Prop> = all
        .iter()
        .map(|c| Prop {
            piece: c.piece,
            at: (f64::from(c.x) + 0.5, f64::from(c.y) + 0.5),
            lands_on: c.lands_on,
            cost: PROP_COST
                + PROP_COST_PER_LAYER * f64::from(bodies[c.piece].bbox.min.z - c.bottom)
                + if c.moves() { MOVE_COST } else { 0.0 },
        })
        .collect();
    let pieces: Vec<usize> = (0..end).collect();
    let contacts: Vec<_> = s.contacts.iter().collect();
    let solved = solve_propped(
        s,
        &pieces,
        &contacts,
        params,
        Some(&Props {
            props: &props,
            cap: TARGET,
        }),
        until,
    )?;
    let strongest = solved.props.iter().copied().fold(0.0, f64::max);
    if strongest < 1e-6 {
        return Ok(Vec::new());
    }
    let mut order: Vec<usize> = (0..all.len()).collect();
    order.sort_by(|&a, &b| solved.props[b].total_cmp(&solved.props[a]).then(a.cmp(&b)));
    let mut chosen: Vec<Candidate> = Vec::new();
    let mut cells: HashSet<(i32, i32)> = HashSet::new();
    for k in order {
        if chosen.len() >= max || solved.props[k] < KEEP_SHARE * strongest {
            break;
        }
        let c = &all[k];
        if c.studs().all(|at| !cells.contains(&at)) {
            cells.extend(c.studs());
            chosen.push(c.clone());
        }
    }
    Ok(chosen)
}

/// `asm` with the `chosen` columns added in steps of their own just
/// before the step of the pieces they hold: the columns holding pieces of
/// one step share steps of at most [`STEP_PIECES`] pieces, whole columns
/// together where they fit, a taller column in balanced parts, bottom up
/// (see [`column_steps`]), and a first such step of one or two pieces
/// joins the step before when it has room; past [`MAX_STEPS`], they join
/// the step they hold instead.
fn insert(
    asm: &Assembly,
    chosen: &[Candidate],
    color: Color,
) -> (Assembly, Vec<Column>, Vec<Placement>) {
    let bodies_z: Vec<i32> = asm.pieces.iter().map(|p| p.placement.origin.z).collect();
    // Each column's pieces, bottom up.
    let parts: Vec<Vec<(PartKind, Rot, i32)>> = chosen
        .iter()
        .map(|c| {
            let (_, _, sx, sy) = c.foot;
            fill(asm.layer_ldu, bodies_z[c.piece] - c.bottom, sx, sy).unwrap_or_default()
        })
        .collect();
    // Columns by the step they hold up, and the steps they take there.
    let mut by_step: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
    for (k, c) in chosen.iter().enumerate() {
        by_step
            .entry(asm.pieces[c.before].step.0)
            .or_default()
            .push(k);
    }
    // Hung pieces that move to stand on their columns.
    let moved: HashSet<usize> = chosen
        .iter()
        .filter(|c| c.moves())
        .map(|c| c.piece)
        .collect();
    // Pieces a step holds.
    let mut held: HashMap<u32, usize> = HashMap::new();
    for p in &asm.pieces {
        *held.entry(p.step.0).or_default() += 1;
    }
    // Each step's plan: the step of each column piece, from 0, and the
    // steps they take; a first step of one or two pieces joins the step
    // before when that has room (their pieces come right after its own).
    let plans: std::collections::BTreeMap<u32, (Vec<Vec<u32>>, u32)> = by_step
        .iter()
        .map(|(&s, ks)| {
            let sizes: Vec<usize> = ks.iter().map(|&k| parts[k].len()).collect();
            let (at, n) = column_steps(&sizes, STEP_PIECES);
            let first = at.iter().flatten().filter(|&&j| j == 0).count();
            let before = held.get(&s.wrapping_sub(1)).copied().unwrap_or(0);
            let join =
                s > 1 && first < STEP_MIN_PIECES && before > 0 && before + first <= STEP_PIECES;
            let at = at
                .into_iter()
                .map(|a| a.into_iter().map(|j| j + u32::from(!join)).collect())
                .collect();
            (s, (at, n - u32::from(join)))
        })
        .collect();
    let added: u32 = plans.values().map(|(_, n)| n).sum();
    let own_steps = asm.step_count() as usize + added as usize <= MAX_STEPS;
    let mut pieces: Vec<Placed> = Vec::with_capacity(asm.pieces.len() + 4 * chosen.len());
    let mut columns = Vec::new();
    let mut placed = Vec::new();
    let mut shift = 0;
    let mut last_step = None;
    for (i, p) in asm.pieces.iter().enumerate() {
        if last_step != Some(p.step.0) {
            last_step = Some(p.step.0);
            if let (Some(ks), Some((at, n))) = (by_step.get(&p.step.0), plans.get(&p.step.0)) {
                // The step before the held one (its number once the
                // columns are in): the columns' steps count from it.
                let first = p.step.0 + shift - 1;
                // Past LeoCAD's steps, all in the held step.
                let step_of = |j: u32| if own_steps { first + j } else { first + 1 };
                for (&k, at) in ks.iter().zip(at) {
                    let c = &chosen[k];
                    let (x0, y0, sx, sy) = c.foot;
                    let mut z = c.bottom;
                    for (&(part, rot, h), &j) in parts[k].iter().zip(at) {
                        let placement = Placement::new(part, Cell::new(x0, y0, z), rot);
                        pieces.push(Placed {
                            placement,
                            step: Step(step_of(j)),
                            color,
                        });
                        placed.push(placement);
                        z += h;
                    }
                    columns.push(Column {
                        x: x0,
                        y: y0,
                        size: [sx, sy],
                        bottom: c.bottom,
                        top: bodies_z[c.piece] - 1,
                        step: step_of(at.first().copied().unwrap_or(1)),
                        last_step: step_of(at.last().copied().unwrap_or(1)),
                        on_ground: c.lands_on.is_none(),
                        pieces: parts[k].len(),
                    });
                }
                if own_steps {
                    shift += n;
                }
                // The hung pieces these columns hold, on them, first in
                // the step of the piece they hung from: on a column under
                // one end, a piece may not stand alone until that piece
                // is on it.
                let mut on: Vec<usize> = ks
                    .iter()
                    .map(|&k| &chosen[k])
                    .filter(|c| c.moves())
                    .map(|c| c.piece)
                    .collect();
                on.sort_unstable();
                on.dedup();
                for q in on {
                    pieces.push(Placed {
                        step: Step(p.step.0 + shift),
                        ..asm.pieces[q]
                    });
                }
            }
        }
        if moved.contains(&i) {
            continue;
        }
        pieces.push(Placed {
            step: Step(p.step.0 + shift),
            ..*p
        });
    }
    (
        Assembly {
            pieces,
            layer_ldu: asm.layer_ldu,
        },
        columns,
        placed,
    )
}

/// The steps of columns of `sizes` pieces built one after the other, at
/// most `cap` pieces a step: for each column, the step (from 0) of each
/// of its pieces, bottom up, and the number of steps. A column joins the
/// step before when both fit in it; a column of more than `cap` pieces
/// takes steps of its own, its pieces shared out evenly among them.
fn column_steps(sizes: &[usize], cap: usize) -> (Vec<Vec<u32>>, u32) {
    let cap = cap.max(1);
    let mut out = Vec::with_capacity(sizes.len());
    // The step being filled and its pieces so far.
    let (mut step, mut held) = (0u32, 0usize);
    for &n in sizes {
        if held > 0 && held + n > cap {
            step += 1;
            held = 0;
        }
        if n <= cap {
            out.push(vec![step; n]);
            held += n;
            continue;
        }
        let k = n.div_ceil(cap);
        let mut at = Vec::with_capacity(n);
        for i in 0..k {
            let len = n / k + usize::from(i < n % k);
            at.extend(std::iter::repeat_n(step, len));
            step += 1;
        }
        out.push(at);
        held = 0;
    }
    let steps = if held > 0 { step + 1 } else { step };
    (out, steps.max(u32::from(!sizes.is_empty())))
}

/// Sets each column's steps from where its pieces are in `asm` (later
/// rounds renumber the steps), and puts them in build order.
pub fn steps_of(asm: &Assembly, columns: &mut [Column]) {
    let at: HashMap<Cell, u32> = asm
        .pieces
        .iter()
        .map(|p| (p.placement.origin, p.step.0))
        .collect();
    for c in columns.iter_mut() {
        // Its pieces: those whose corner is on its corner, bottom to top
        // (only the column fills those cells).
        let steps: Vec<u32> = (c.bottom..=c.top)
            .filter_map(|z| at.get(&Cell::new(c.x, c.y, z)).copied())
            .collect();
        if let (Some(&first), Some(&last)) = (steps.first(), steps.iter().max()) {
            c.step = first;
            c.last_step = last;
        }
    }
    columns.sort_by_key(|c| (c.step, c.bottom, c.y, c.x));
}

/// A colour for support columns that none of `assembly`'s pieces has:
/// light bluish grey, else dark bluish grey, black or white.
pub fn support_color(assembly: &Assembly) -> Color {
    let used: HashSet<Color> = assembly.pieces.iter().map(|p| p.color).collect();
    [Color(71), Color(72), Color(0), Color(15)]
        .into_iter()
        .find(|c| !used.contains(c))
        .unwrap_or(Color(71))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{analyze, analyze_steps};

    fn piece(id: &str, x: i32, z: i32, step: u32) -> Placed {
        Placed {
            placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0),
            step: Step(step),
            color: Color::RED,
        }
    }

    /// A post of three 1 x 1 bricks and a 1 x 6 arm on top reaching five
    /// studs past it: on a table the post tips over.
    fn gallows() -> Assembly {
        Assembly {
            pieces: vec![
                piece("3005", 0, 0, 1),
                piece("3005", 0, 1, 2),
                piece("3005", 0, 2, 3),
                piece("3009", 0, 3, 4),
            ],
            layer_ldu: 24,
        }
    }

    #[test]
    fn a_column_under_the_arm_makes_the_gallows_stand() {
        let params = Params::default();
        let asm = gallows();
        assert!(!analyze(&asm, &params).unwrap().stands());
        let shored = shore_up(&asm, &params, Upto::Finished, 0, Color(71), None, false)
            .unwrap()
            .expect("a column");
        assert!(shored.stands);
        assert!(analyze(&shored.assembly, &params).unwrap().stands());
        let check = analyze_steps(&shored.assembly, &params, false).unwrap();
        assert_eq!(check.first_failure, None, "{check:?}");
        assert!(verify(&shored.assembly, None).is_ok());
        // One column from the table up to the arm, away from the post, in a
        // step of its own before the arm's.
        assert_eq!(shored.columns.len(), 1);
        let c = &shored.columns[0];
        assert!(c.on_ground && c.bottom == 0 && c.top == 2, "{c:?}");
        assert!((1..=5).contains(&c.x), "{c:?}");
        // The widest that stays within the model's footprint: two studs
        // along the arm (which is one stud deep).
        assert_eq!(c.size, [2, 1], "{c:?}");
        assert_eq!(c.pieces, 3);
        assert_eq!(shored.pieces.len(), 3);
        let arm = shored
            .assembly
            .pieces
            .iter()
            .find(|p| p.placement.part.spec().id.0 == "3009")
            .unwrap();
        assert_eq!(c.step + 1, arm.step.0);
        let steps: Vec<u32> = shored.assembly.pieces.iter().map(|p| p.step.0).collect();
        assert_eq!(steps, [1, 2, 3, 4, 4, 4, 5]);
        let support: Vec<&Placed> = shored
            .assembly
            .pieces
            .iter()
            .filter(|p| p.color == Color(71))
            .collect();
        assert_eq!(support.len(), 3);
        assert!(support
            .iter()
            .all(|p| p.placement.part.spec().id.0 == "3004"));
        // Nothing the model fills is taken.
        let model: HashSet<Cell> = asm
            .pieces
            .iter()
            .flat_map(|p| p.placement.body(24).cells().collect::<Vec<_>>())
            .collect();
        for p in support {
            assert!(p.placement.body(24).cells().all(|c| !model.contains(&c)));
        }
        // The same input gives the same columns.
        let again = shore_up(&asm, &params, Upto::Finished, 0, Color(71), None, false)
            .unwrap()
            .unwrap();
        assert_eq!(again.assembly, shored.assembly);
    }

    #[test]
    fn a_short_column_joins_the_step_before() {
        // The gallows a brick lower: a column of two pieces, which joins
        // the post's top brick's step rather than make a step of two.
        let params = Params::default();
        let asm = Assembly {
            pieces: vec![
                piece("3005", 0, 0, 1),
                piece("3005", 0, 1, 2),
                piece("3009", 0, 2, 3),
            ],
            layer_ldu: 24,
        };
        assert!(!analyze(&asm, &params).unwrap().stands());
        let shored = shore_up(&asm, &params, Upto::Finished, 0, Color(71), None, false)
            .unwrap()
            .expect("a column");
        assert!(shored.stands);
        let check = analyze_steps(&shored.assembly, &params, false).unwrap();
        assert_eq!(check.first_failure, None, "{check:?}");
        assert!(verify(&shored.assembly, None).is_ok());
        assert_eq!(shored.columns.len(), 1);
        let c = &shored.columns[0];
        assert_eq!((c.pieces, c.step, c.last_step), (2, 2, 2), "{c:?}");
        let steps: Vec<u32> = shored.assembly.pieces.iter().map(|p| p.step.0).collect();
        assert_eq!(steps, [1, 2, 2, 2, 3]);
    }

    #[test]
    fn columns_share_steps_of_a_builders_size() {
        // Whole columns together where they fit, bottom up.
        assert_eq!(
            column_steps(&[3, 2, 4], 8),
            (vec![vec![0; 3], vec![0; 2], vec![1; 4]], 2)
        );
        // Four columns of five: a column a step.
        let (at, n) = column_steps(&[5; 4], 8);
        assert_eq!(n, 4);
        assert_eq!(at[3], vec![3; 5]);
        // A tall column in balanced parts, the next column after it.
        assert_eq!(
            column_steps(&[11, 2], 8),
            (vec![vec![0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1], vec![2, 2]], 3)
        );
        assert_eq!(column_steps(&[1], 8), (vec![vec![0]], 1));
    }

    #[test]
    fn a_step_is_shored_up_with_columns_before_it_and_a_standing_build_is_left_alone() {
        let params = Params::default();
        let asm = gallows();
        let shored = shore_up(&asm, &params, Upto::Step(4), 0, Color(71), None, false)
            .unwrap()
            .expect("a column");
        assert!(shored.stands);
        assert_eq!(shored.columns.len(), 1);
        // Up to step 3 the post stands: nothing to do.
        assert!(
            shore_up(&asm, &params, Upto::Step(3), 0, Color(71), None, false)
                .unwrap()
                .is_none()
        );
        // No room left for columns: nothing added.
        assert!(shore_up(
            &asm,
            &params,
            Upto::Finished,
            MAX_COLUMNS,
            Color(71),
            None,
            false
        )
        .unwrap()
        .is_none());
    }

    #[test]
    fn plate_grids_top_columns_with_plates() {
        // Bricks are three layers of a plate grid: seven layers are two
        // bricks and a plate.
        let parts = fill(8, 7, 1, 1).unwrap();
        let ids: Vec<&str> = parts.iter().map(|(p, _, _)| p.spec().id.0).collect();
        assert_eq!(ids, ["3005", "3005", "3024"]);
        let parts = fill(8, 4, 2, 2).unwrap();
        let ids: Vec<&str> = parts.iter().map(|(p, _, _)| p.spec().id.0).collect();
        assert_eq!(ids, ["3003", "3022"]);
        // A 1 x 2 footprint is a 2 x 1 brick turned a quarter.
        let (part, rot, _) = fill(24, 1, 1, 2).unwrap()[0];
        assert_eq!(part.spec().footprint(rot), (1, 2));
        // A slope grid (half bricks) has no piece for an odd layer.
        assert!(fill(12, 3, 1, 1).is_none());
        assert_eq!(fill(12, 4, 2, 1).unwrap().len(), 2);
    }
}
