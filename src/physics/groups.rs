//! Groups of touching pieces, kept as pieces are added step by step: a
//! union-find over the pieces, and for each step the groups that grew (the
//! programs the step check solves).
//!
//! A group lists all its pieces, so the groups of every step at once take
//! memory growing with the square of the steps (a column of bricks, one a
//! step: each step's one group holds every brick so far). [`JobWindow`]
//! makes them as the check reaches them, a batch of steps ahead, and drops
//! them once it has passed.

use super::model::Structure;

/// Union-find over piece indices, with whether each group touches the
/// ground.
pub(super) struct Groups {
    parent: Vec<usize>,
    grounded: Vec<bool>,
}

impl Groups {
    pub(super) fn new() -> Groups {
        Groups {
            parent: Vec::new(),
            grounded: Vec::new(),
        }
    }

    pub(super) fn add(&mut self, grounded: bool) {
        self.parent.push(self.parent.len());
        self.grounded.push(grounded);
    }

    pub(super) fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // The smaller index becomes the root: deterministic.
            let (root, child) = (ra.min(rb), ra.max(rb));
            self.parent[child] = root;
            self.grounded[root] |= self.grounded[child];
        }
    }
}

/// One program to solve: a group of the build after some step.
pub(super) struct Job {
    /// The group's pieces, sorted.
    pub(super) pieces: Vec<usize>,
    /// Indices into the structure's contacts.
    pub(super) contacts: Vec<usize>,
    pub(super) grounded: bool,
}

/// Advances the groups to the first `end` pieces and returns a job for
/// every group that gained pieces, with `reused` counting the groups that
/// did not.
pub(super) fn jobs_for_step(
    s: &Structure,
    g: &mut Groups,
    next_contact: &mut usize,
    end: usize,
    reused: &mut usize,
) -> Vec<Job> {
    let touched = grow_groups(s, g, next_contact, end, reused);
    let c = *next_contact;
    let roots: Vec<usize> = (0..end).map(|p| g.find(p)).collect();
    touched
        .into_iter()
        .map(|root| Job {
            pieces: (0..end).filter(|&p| roots[p] == root).collect(),
            contacts: (0..c)
                .filter(|&k| roots[s.contacts[k].below] == root)
                .collect(),
            grounded: g.grounded[root],
        })
        .collect()
}

/// The groups of the steps, made a few steps ahead of the check and
/// dropped once it has passed them: memory for the steps in reach, not for
/// all of them.
pub(super) struct JobWindow<'a> {
    s: &'a Structure,
    bounds: &'a [(u32, usize)],
    /// The first step checked (see `check_steps_in`).
    k0: usize,
    groups: Groups,
    next_contact: usize,
    /// Steps before this one have their jobs made (or skipped).
    made: usize,
    /// Groups that did not grow, summed over the steps made.
    reused: usize,
    /// The made steps' jobs not yet taken, by step.
    jobs: std::collections::BTreeMap<usize, Vec<Job>>,
}

impl<'a> JobWindow<'a> {
    pub(super) fn new(s: &'a Structure, bounds: &'a [(u32, usize)], k0: usize) -> Self {
        JobWindow {
            s,
            bounds,
            k0,
            groups: Groups::new(),
            next_contact: 0,
            made: 0,
            reused: 0,
            jobs: std::collections::BTreeMap::new(),
        }
    }

    /// Makes the jobs of every step before `upto` (at most the last).
    pub(super) fn make_to(&mut self, upto: usize) {
        while self.made < upto.min(self.bounds.len()) {
            let k = self.made;
            let jobs = self.advance(k);
            self.jobs.insert(k, jobs);
            self.made += 1;
        }
    }

    /// Moves the groups on past every step before `upto` without keeping
    /// their jobs (steps skipped, or solved whole).
    pub(super) fn skip_to(&mut self, upto: usize) {
        while self.made < upto.min(self.bounds.len()) {
            self.advance(self.made);
            self.made += 1;
        }
    }

    /// The groups after step `k`, and the jobs of those that grew.
    fn advance(&mut self, k: usize) -> Vec<Job> {
        let before = self.reused;
        let jobs = jobs_for_step(
            self.s,
            &mut self.groups,
            &mut self.next_contact,
            self.bounds[k].1,
            &mut self.reused,
        );
        if self.k0 > 0 && k <= self.k0 {
            // Skipped, or solved whole: nothing of it is reused.
            self.reused = before;
        }
        jobs
    }

    /// The jobs of step `k` (made), for the check to use; earlier steps'
    /// are dropped.
    pub(super) fn take(&mut self, k: usize) -> Vec<Job> {
        while let Some(first) = self.jobs.first_key_value().map(|(&f, _)| f) {
            if first >= k {
                break;
            }
            self.jobs.remove(&first);
        }
        self.jobs.remove(&k).unwrap_or_default()
    }

    /// The groups that did not grow, over every step, those the check did
    /// not reach included (counted, their jobs not kept).
    pub(super) fn finish(mut self) -> usize {
        while self.made < self.bounds.len() {
            let k = self.made;
            let before = self.reused;
            grow_groups(
                self.s,
                &mut self.groups,
                &mut self.next_contact,
                self.bounds[k].1,
                &mut self.reused,
            );
            if self.k0 > 0 && k <= self.k0 {
                self.reused = before;
            }
            self.made += 1;
        }
        self.reused
    }
}

/// Advances the groups to the first `end` pieces, adding to `reused` the
/// groups that did not grow, and returns the roots of those that did.
fn grow_groups(
    s: &Structure,
    g: &mut Groups,
    next_contact: &mut usize,
    end: usize,
    reused: &mut usize,
) -> Vec<usize> {
    let start = g.parent.len();
    for p in start..end {
        g.add(s.grounded(p));
    }
    let mut c = *next_contact;
    while c < s.contacts.len() && s.contacts[c].below.max(s.contacts[c].above) < end {
        g.union(s.contacts[c].below, s.contacts[c].above);
        c += 1;
    }
    *next_contact = c;
    let mut touched: Vec<usize> = (start..end).map(|p| g.find(p)).collect();
    touched.sort_unstable();
    touched.dedup();
    let groups = (0..end).filter(|&p| g.find(p) == p).count();
    *reused += groups - touched.len();
    touched
}
