//! The packed composite configuration space CSS of Ben-Shahar & Rivlin §II-A: a configuration
//! Q = (q_𝓡, q_𝓜₁, …, q_𝓜ᵣ) as one integer in mixed radix ([`PackedIndex`]), its decoding, the free-space test
//! (CCF) and the goal set.

use super::super::grid::Dir;
use super::model::Model;
use super::spec::{Config, Placement};
use super::tables::{Domain, MAX_MOVABLES, NONE, PackedIndex, State};

impl Model {
    /// Grid width.
    pub fn w(&self) -> i32 {
        self.problem.grid.w
    }
    /// Grid height.
    pub fn h(&self) -> i32 {
        self.problem.grid.h
    }
    /// Number of movables.
    pub fn r(&self) -> usize {
        self.movables.len()
    }

    /// Does the packed space need `u64` indices (2³² configurations or more)?
    pub fn wide(&self) -> bool {
        self.n_states > u32::MAX as u64
    }

    /// Decode a packed index.
    #[inline]
    pub fn decode<I: PackedIndex>(&self, idx: I) -> State {
        let mut s = State {
            aux: 0,
            r: 0,
            m: [0; MAX_MOVABLES],
        };
        let mut x = idx;
        if self.n_aux > 1 {
            (x, s.aux) = x.div_rem(self.div[0]);
        }
        (x, s.r) = x.div_rem(self.div[1]);
        for i in 0..self.r() {
            (x, s.m[i]) = x.div_rem(self.div[2 + i]);
        }
        s
    }

    /// Encode local indices.
    #[inline]
    pub fn encode<I: PackedIndex>(&self, s: &State) -> I {
        let mut x = I::from_u64(0);
        for i in (0..self.r()).rev() {
            x = x.push_digit(self.radix[2 + i], s.m[i]);
        }
        x.push_digit(self.radix[1], s.r)
            .push_digit(self.radix[0], s.aux)
    }

    /// Are the two bodies overlapping? (robot vs movable i)
    #[inline]
    pub fn rm_overlap(&self, i: usize, r: u32, m: u32) -> bool {
        self.rm[i].get(m as usize * self.radix[1] as usize + r as usize)
    }

    /// Are movables i and j (i ≠ j) overlapping?
    #[inline]
    pub fn mm_overlap(&self, i: usize, mi: u32, j: usize, mj: u32) -> bool {
        if i < j {
            match &self.mm[i * MAX_MOVABLES + j] {
                Some(b) => b.get(mi as usize * self.radix[2 + j] as usize + mj as usize),
                None => false,
            }
        } else {
            self.mm_overlap(j, mj, i, mi)
        }
    }

    /// Is a decoded state in the free space CCF (no two bodies overlap)?
    #[inline]
    pub fn valid(&self, s: &State) -> bool {
        let r = self.r();
        for i in 0..r {
            if self.rm_overlap(i, s.r, s.m[i]) {
                return false;
            }
            for j in i + 1..r {
                if self.mm_overlap(i, s.m[i], j, s.m[j]) {
                    return false;
                }
            }
        }
        true
    }

    /// Robot memory index for a last move.
    #[inline]
    pub fn aux_of(&self, dir: Dir, pushing: bool) -> u32 {
        if self.n_aux == 1 {
            0
        } else {
            dir as u32 * 2 + pushing as u32
        }
    }

    /// Pack a grid configuration (None if outside CCF).
    pub fn pack(&self, c: &Config) -> Option<u64> {
        if c.movables.len() != self.r() {
            return None;
        }
        let (w, h) = (self.w(), self.h());
        let r = self.robot.lookup(
            w,
            h,
            Placement {
                x: c.robot.0,
                y: c.robot.1,
                o: 0,
            },
        );
        if r == NONE {
            return None;
        }
        let mut s = State {
            aux: self.aux_of(c.heading, c.pushing),
            r,
            m: [0; MAX_MOVABLES],
        };
        for (i, p) in c.movables.iter().enumerate() {
            let l = self.movables[i].lookup(w, h, *p);
            if l == NONE {
                return None;
            }
            s.m[i] = l;
        }
        self.valid(&s).then(|| self.encode(&s))
    }

    /// Unpack an index into grid terms.
    pub fn unpack(&self, idx: u64) -> Config {
        let s = self.decode(idx);
        let rp = self.robot.place[s.r as usize];
        Config {
            robot: (rp.x, rp.y),
            heading: Dir::from_index((s.aux / 2) as usize),
            pushing: self.n_aux > 1 && s.aux % 2 == 1,
            movables: (0..self.r())
                .map(|i| self.movables[i].place[s.m[i] as usize])
                .collect(),
        }
    }

    /// The goal set: every configuration in CCF with each body at its goal (or anywhere).
    pub fn goal_states(&self) -> Vec<u64> {
        let p = &self.problem;
        let (w, h) = (self.w(), self.h());
        let choices = |dom: &Domain, g: Option<Placement>| -> Vec<u32> {
            match g {
                Some(pl) => {
                    let l = dom.lookup(w, h, pl);
                    if l == NONE { vec![] } else { vec![l] }
                }
                None => (0..dom.len()).collect(),
            }
        };
        let rob = choices(
            &self.robot,
            p.goal_robot.map(|(x, y)| Placement { x, y, o: 0 }),
        );
        let ms: Vec<Vec<u32>> = (0..self.r())
            .map(|i| choices(&self.movables[i], p.goal_movables[i]))
            .collect();
        let mut out = Vec::new();
        let mut s = State {
            aux: 0,
            r: 0,
            m: [0; MAX_MOVABLES],
        };
        let mut digits = vec![0usize; self.r()];
        if ms.iter().any(|v| v.is_empty()) {
            return out;
        }
        loop {
            for i in 0..self.r() {
                s.m[i] = ms[i][digits[i]];
            }
            let movables_ok = (0..self.r())
                .all(|i| (i + 1..self.r()).all(|j| !self.mm_overlap(i, s.m[i], j, s.m[j])));
            if movables_ok {
                for &r in &rob {
                    s.r = r;
                    if (0..self.r()).all(|i| !self.rm_overlap(i, r, s.m[i])) {
                        for a in 0..self.n_aux {
                            s.aux = a;
                            out.push(self.encode(&s));
                        }
                    }
                }
            }
            // next combination
            let mut k = 0;
            loop {
                if k == self.r() {
                    return out;
                }
                digits[k] += 1;
                if digits[k] < ms[k].len() {
                    break;
                }
                digits[k] = 0;
                k += 1;
            }
        }
    }
}
