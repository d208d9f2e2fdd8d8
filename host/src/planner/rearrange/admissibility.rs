//! Admissible neighbours N_A(Q) and admissible origins N_A⁻¹(Q), Ben-Shahar & Rivlin §IV-B.
//!
//! Both are computed on the fly from the packed configuration; the graph is never stored.
//! A move is one step of the robot in a main direction:
//! - a **transit** move when the robot's new cells touch no movable;
//! - a **translational push** when they do: the movables the robot runs into, and the movables
//!   those run into (a chain), all move one cell with it. It is admissible when the direction is
//!   allowed, no more than `max_pushed` movables move, none is blocked, and (with
//!   `strict_contact`) the robot touches each movable it runs into through one of its contact
//!   modes;
//! - a **rotational push** (3-DOF movables, Fig. 18): the robot stands at a rotational contact
//!   mode and steps; the movable turns 90° and lands aligned with the grid again (§V-A). The
//!   bounding box of the movable before and after the turn must be free of obstacles and of other
//!   movables (the robot may be in it).
//!
//! After every move, each movable that is not being pushed must lie where movables may be left
//! and (with a distance limit) within that Manhattan distance of the robot (anchor to anchor).
//!
//! Origins are found by undoing each kind of move and then replaying the forward move from the
//! candidate: a candidate Q̂ is an origin of Q exactly when the forward move from Q̂ lands on Q.

// Movable indices address several parallel arrays (placements, tables, masks) at once.
#![allow(clippy::needless_range_loop)]

use super::metric::StepKind;
use super::problem::{Dir, MAX_MOVABLES, Model, NONE, PackedIndex, RotInstance, State};

/// What a move does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveKind {
    /// The robot moves alone.
    Transit,
    /// The robot translates the movables in this bit mask.
    Push {
        /// Bit i: movable i moved (the practical mode's plans number up to 64 movables).
        pushed: u64,
    },
    /// The robot turns one movable by a quarter turn.
    Rotate {
        /// Which movable.
        movable: u8,
        /// +1 clockwise, −1 counter-clockwise (on screen).
        turn: i8,
    },
}

/// One admissible move from a configuration (its packed index an `I`, `u64` unless said).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step<I = u64> {
    /// The configuration it leads to.
    pub to: I,
    /// Its cost D(Q, to).
    pub cost: u32,
    /// The robot's direction of motion.
    pub dir: Dir,
    /// What it does.
    pub kind: MoveKind,
}

impl Model {
    #[inline]
    fn prev_memory(&self, aux: u32) -> Option<(Dir, bool)> {
        if self.n_aux == 1 {
            None
        } else {
            Some((Dir::from_index((aux / 2) as usize), aux % 2 == 1))
        }
    }

    /// After a move: movables not pushed (bit mask) may be left where they are and are close
    /// enough to the robot.
    #[inline]
    fn arrival_ok(&self, r: u32, m: &[u32; MAX_MOVABLES], pushed: u32) -> bool {
        let limit = self.problem.rules.distance_limit;
        let rp = self.robot.place[r as usize];
        for (j, &mj) in m.iter().enumerate().take(self.r()) {
            if pushed & (1 << j) != 0 {
                continue;
            }
            if !self.leave_ok[j][mj as usize] {
                return false;
            }
            if let Some(l) = limit {
                let mp = self.movables[j].place[mj as usize];
                if (rp.x - mp.x).unsigned_abs() + (rp.y - mp.y).unsigned_abs() > l {
                    return false;
                }
            }
        }
        true
    }

    /// The robot steps in `d` from `s` (transit or translational push), if admissible.
    pub fn try_step(&self, s: &State, d: Dir) -> Option<(State, u32, MoveKind)> {
        let r2 = self.robot.shift[s.r as usize * 4 + d as usize];
        if r2 == NONE {
            return None;
        }
        let n = self.r();
        let mut mask = 0u32;
        for i in 0..n {
            if self.rm_overlap(i, r2, s.m[i]) {
                mask |= 1 << i;
            }
        }
        let prev = self.prev_memory(s.aux);
        let metric = &self.problem.metric;
        if mask == 0 {
            if !self.arrival_ok(r2, &s.m, 0) {
                return None;
            }
            let cost =
                self.robot_cost[r2 as usize] + metric.memory_cost(prev, d, StepKind::Transit);
            let t = State {
                aux: self.aux_of(d, false),
                r: r2,
                m: s.m,
            };
            return Some((t, cost, MoveKind::Transit));
        }
        let rules = &self.problem.rules;
        if rules.push_dirs & (1 << d as u8) == 0 {
            return None;
        }
        if rules.strict_contact {
            let rp = self.robot.place[s.r as usize];
            for i in 0..n {
                if mask & (1 << i) != 0 {
                    let mp = self.movables[i].place[s.m[i] as usize];
                    if !self.contact[i].allows(mp.o, d, rp.x - mp.x, rp.y - mp.y) {
                        return None;
                    }
                }
            }
        }
        let mut m2 = s.m;
        let mut frontier = mask;
        while frontier != 0 {
            let mut added = 0u32;
            for i in 0..n {
                if frontier & (1 << i) == 0 {
                    continue;
                }
                let ni = self.movables[i].shift[s.m[i] as usize * 4 + d as usize];
                if ni == NONE {
                    return None;
                }
                m2[i] = ni;
                for j in 0..n {
                    if (mask | added) & (1 << j) == 0 && self.mm_overlap(i, ni, j, s.m[j]) {
                        added |= 1 << j;
                    }
                }
            }
            mask |= added;
            frontier = added;
        }
        let count = mask.count_ones();
        if rules.max_pushed != 0 && count > rules.max_pushed as u32 {
            return None;
        }
        if !self.arrival_ok(r2, &m2, mask) {
            return None;
        }
        let mut cost =
            self.robot_cost[r2 as usize] + metric.memory_cost(prev, d, StepKind::Translate);
        for (i, &mi) in m2.iter().enumerate().take(n) {
            if mask & (1 << i) != 0 {
                cost += self.push_cost[i][mi as usize];
            }
        }
        let t = State {
            aux: self.aux_of(d, true),
            r: r2,
            m: m2,
        };
        Some((
            t,
            cost,
            MoveKind::Push {
                pushed: mask as u64,
            },
        ))
    }

    /// The robot turns movable `i` with a rotational push, if admissible.
    pub fn try_rotate(&self, s: &State, i: usize, inst: &RotInstance) -> Option<(State, u32)> {
        let mp = self.movables[i].place[s.m[i] as usize];
        let rp = self.robot.place[s.r as usize];
        if mp.o != inst.pre_o || (rp.x - mp.x, rp.y - mp.y) != inst.robot_off {
            return None;
        }
        let r2 = self.robot.shift[s.r as usize * 4 + inst.dir as usize];
        if r2 == NONE {
            return None;
        }
        let post = super::problem::Placement {
            x: mp.x + inst.shift.0,
            y: mp.y + inst.shift.1,
            o: inst.post_o,
        };
        let m2i = self.movables[i].lookup(self.w(), self.h(), post);
        if m2i == NONE || self.rm_overlap(i, r2, m2i) {
            return None;
        }
        for j in 0..self.r() {
            if j != i && (self.rm_overlap(j, r2, s.m[j]) || self.mm_overlap(i, m2i, j, s.m[j])) {
                return None;
            }
        }
        let g = &self.problem.grid;
        for &(cx, cy) in &inst.sweep {
            let (x, y) = (mp.x + cx, mp.y + cy);
            if !g.free(x, y) {
                return None;
            }
            let c = (y * g.w + x) as u32;
            for j in 0..self.r() {
                if j != i && self.movables[j].cells[s.m[j] as usize].contains(&c) {
                    return None;
                }
            }
        }
        let mut m2 = s.m;
        m2[i] = m2i;
        if !self.arrival_ok(r2, &m2, 1 << i) {
            return None;
        }
        let prev = self.prev_memory(s.aux);
        let cost = self.robot_cost[r2 as usize]
            + self.push_cost[i][m2i as usize]
            + self
                .problem
                .metric
                .memory_cost(prev, inst.dir, StepKind::Rotate);
        Some((
            State {
                aux: self.aux_of(inst.dir, false),
                r: r2,
                m: m2,
            },
            cost,
        ))
    }

    /// The admissible neighbours N_A(Q) of a packed configuration, with their costs.
    pub fn neighbours<I: PackedIndex>(&self, idx: I, out: &mut Vec<Step<I>>) {
        out.clear();
        let s = self.decode(idx);
        if !self.valid(&s) {
            return;
        }
        for d in Dir::ALL {
            if let Some((t, cost, kind)) = self.try_step(&s, d) {
                out.push(Step {
                    to: self.encode(&t),
                    cost,
                    dir: d,
                    kind,
                });
            }
        }
        for i in 0..self.r() {
            let o = self.movables[i].place[s.m[i] as usize].o;
            for inst in &self.rot_pre[i][o as usize] {
                if let Some((t, cost)) = self.try_rotate(&s, i, inst) {
                    let turn = if (inst.post_o + 4 - inst.pre_o) % 4 == 1 {
                        1
                    } else {
                        -1
                    };
                    out.push(Step {
                        to: self.encode(&t),
                        cost,
                        dir: inst.dir,
                        kind: MoveKind::Rotate {
                            movable: i as u8,
                            turn,
                        },
                    });
                }
            }
        }
    }

    /// The admissible origins N_A⁻¹(Q) ∩ CCF of a packed configuration, each with D(Q̂, Q).
    /// `idx` must be in CCF.
    pub fn origins<I: PackedIndex>(&self, idx: I, out: &mut Vec<(I, u32)>) {
        out.clear();
        let q = self.decode(idx);
        let n = self.r();
        let metric = &self.problem.metric;
        // With memory, the arriving move's direction and kind are known from Q itself.
        let (dirs, transit_ok, push_ok): (&[Dir], bool, bool) = if self.n_aux == 1 {
            (&Dir::ALL, true, true)
        } else {
            let d = (q.aux / 2) as usize;
            (
                &Dir::ALL[d..d + 1],
                q.aux.is_multiple_of(2),
                !q.aux.is_multiple_of(2),
            )
        };
        let transit_arrival = transit_ok && self.arrival_ok(q.r, &q.m, 0);
        // Origins differ from Q in a few digits: build their indices by strides, not by encoding.
        let base = idx.with_digit(1, q.aux, 0);
        let sr = self.stride[1] as u32; // the robot memory's radix: 1 or 8
        let touching = (0..n)
            .any(|i| self.touch[i].get(q.m[i] as usize * self.radix[1] as usize + q.r as usize));
        for &d in dirs {
            let rh = self.robot.shift[q.r as usize * 4 + d.opposite() as usize];
            if rh == NONE {
                continue;
            }
            if transit_arrival && (0..n).all(|i| !self.rm_overlap(i, rh, q.m[i])) {
                let c0 = self.robot_cost[q.r as usize];
                let b = base.with_digit(sr, q.r, rh);
                if self.n_aux == 1 {
                    out.push((b, c0));
                } else {
                    for a in 0..self.n_aux {
                        let c = c0 + metric.memory_cost(self.prev_memory(a), d, StepKind::Transit);
                        out.push((b.plus(a), c));
                    }
                }
            }
            if !touching || !push_ok || self.problem.rules.push_dirs & (1 << d as u8) == 0 {
                continue;
            }
            // Movables the robot may have run into: undone by one cell, under the robot's new cells.
            let mut mh = [NONE; MAX_MOVABLES];
            let mut direct = 0u32;
            for i in 0..n {
                mh[i] = self.movables[i].shift[q.m[i] as usize * 4 + d.opposite() as usize];
                if mh[i] != NONE && self.rm_overlap(i, q.r, mh[i]) {
                    direct |= 1 << i;
                }
            }
            if direct == 0 {
                continue;
            }
            for set in 1u32..(1 << n) {
                if set & direct == 0 || (0..n).any(|i| set & (1 << i) != 0 && mh[i] == NONE) {
                    continue;
                }
                let mut p = q;
                p.r = rh;
                for i in 0..n {
                    if set & (1 << i) != 0 {
                        p.m[i] = mh[i];
                    }
                }
                if !self.valid(&p) {
                    continue;
                }
                for a in 0..self.n_aux {
                    p.aux = a;
                    if let Some((t, c, _)) = self.try_step(&p, d)
                        && t == q
                    {
                        out.push((self.encode(&p), c));
                    }
                }
            }
        }
        if !transit_ok || !self.any_rotation {
            return;
        }
        for i in 0..n {
            let mp = self.movables[i].place[q.m[i] as usize];
            for inst in &self.rot_post[i][mp.o as usize] {
                if !dirs.contains(&inst.dir) {
                    continue;
                }
                let pre = super::problem::Placement {
                    x: mp.x - inst.shift.0,
                    y: mp.y - inst.shift.1,
                    o: inst.pre_o,
                };
                let mhi = self.movables[i].lookup(self.w(), self.h(), pre);
                if mhi == NONE {
                    continue;
                }
                let rpre = super::problem::Placement {
                    x: pre.x + inst.robot_off.0,
                    y: pre.y + inst.robot_off.1,
                    o: 0,
                };
                let rh = self.robot.lookup(self.w(), self.h(), rpre);
                if rh == NONE || self.robot.shift[rh as usize * 4 + inst.dir as usize] != q.r {
                    continue;
                }
                let mut p = q;
                p.r = rh;
                p.m[i] = mhi;
                if !self.valid(&p) {
                    continue;
                }
                for a in 0..self.n_aux {
                    p.aux = a;
                    if let Some((t, c)) = self.try_rotate(&p, i, inst)
                        && t == q
                    {
                        out.push((self.encode(&p), c));
                    }
                }
            }
        }
    }
}
