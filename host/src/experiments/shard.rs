//! Sweeps spread over machines: `--shard K/N` runs the K-th of N shares of a sweep's cells,
//! dealt deterministically from the sweep's own list, so N processes on N machines (a Slurm job
//! array, a Kubernetes indexed Job, GNU `parallel`) run every cell exactly once between them
//! with no scheduler of ours. Each shard keeps its cells in its own `--resume` file, whose
//! header names the sweep and the share ([`Sweep`]); `pushbot eval merge` joins the files into
//! the one table and figure, and refuses files of another sweep.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::trials::Method;

/// The K-th of N shares of a sweep (1 ≤ K ≤ N).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which share, from 1.
    pub k: usize,
    /// How many shares.
    pub n: usize,
}

impl FromStr for Shard {
    type Err = String;

    /// `K/N`, as `2/3`.
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard takes K/N with 1 ≤ K ≤ N (as 2/3), not {s:?}");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || k > n || n > 10_000 {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl Shard {
    /// Whether cell `index` of the sweep's list is this share's. Cells are dealt like cards
    /// going back and forth along the shards (0, 1, …, N−1, N−1, …, 0, 0, 1, …), so that
    /// neighbouring cells (the same start with each method) spread over the shards.
    pub fn owns(&self, index: usize) -> bool {
        let (round, seat) = (index / self.n, index % self.n);
        let dealt = if round % 2 == 0 {
            seat
        } else {
            self.n - 1 - seat
        };
        dealt + 1 == self.k
    }
}

/// What a sharded delivery sweep is: its cells are every scene × start × method, in this
/// order, and its shard is one share of them. Kept in the header of each shard's file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    /// This file's share.
    pub shard: Shard,
    /// The scenes, in order.
    pub scenes: Vec<String>,
    /// The start positions, in order.
    pub starts: Vec<String>,
    /// The methods, in order.
    pub methods: Vec<Method>,
    /// The paper's figure the sweep draws (`--figure`), if any.
    pub figure: Option<u8>,
    /// The object delivered (`--object`; the scene's first when `None`).
    pub object: Option<String>,
}

impl Sweep {
    /// The index of a cell in the sweep's list.
    pub fn index(&self, scene: usize, start: usize, method: usize) -> usize {
        (scene * self.starts.len() + start) * self.methods.len() + method
    }

    /// Whether the cell of `scene`, `start` and `method` (indices) is this shard's.
    pub fn owns(&self, scene: usize, start: usize, method: usize) -> bool {
        self.shard.owns(self.index(scene, start, method))
    }

    /// How many cells the whole sweep has.
    pub fn cells(&self) -> usize {
        self.scenes.len() * self.starts.len() * self.methods.len()
    }

    /// The sweep without its share (what every shard's file must agree on).
    pub fn unsharded(&self) -> Sweep {
        Sweep {
            shard: Shard {
                k: 1,
                n: self.shard.n,
            },
            ..self.clone()
        }
    }

    /// What differs between this sweep and `file`'s, in words.
    pub fn differences(&self, file: &Sweep) -> Vec<String> {
        let list = |v: &[String]| v.join(",");
        let methods = |v: &[Method]| {
            v.iter()
                .map(|m| format!("{m:?}").to_lowercase())
                .collect::<Vec<_>>()
                .join(",")
        };
        let figure = |f: Option<u8>| f.map_or("none".to_owned(), |f| f.to_string());
        [
            ("shard", self.shard.to_string(), file.shard.to_string()),
            ("scenes", list(&self.scenes), list(&file.scenes)),
            ("starts", list(&self.starts), list(&file.starts)),
            ("methods", methods(&self.methods), methods(&file.methods)),
            ("figure", figure(self.figure), figure(file.figure)),
            (
                "object",
                self.object.clone().unwrap_or_default(),
                file.object.clone().unwrap_or_default(),
            ),
        ]
        .into_iter()
        .filter(|(_, a, b)| a != b)
        .map(|(name, a, b)| format!("{name} {b} in the file, {a} now"))
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell belongs to exactly one share, and the shares differ in size by at most one.
    #[test]
    fn every_cell_is_dealt_to_exactly_one_shard_evenly() {
        for n in 1..=7 {
            for cells in 0..50 {
                let mut sizes = vec![0usize; n];
                for i in 0..cells {
                    let owners: Vec<usize> = (1..=n).filter(|&k| Shard { k, n }.owns(i)).collect();
                    assert_eq!(
                        owners.len(),
                        1,
                        "cell {i} of {cells}, {n} shards: {owners:?}"
                    );
                    sizes[owners[0] - 1] += 1;
                }
                let (lo, hi) = (sizes.iter().min(), sizes.iter().max());
                assert!(
                    hi.unwrap() - lo.unwrap() <= 1,
                    "{cells} cells / {n}: {sizes:?}"
                );
            }
        }
        // Two methods on two shards: each shard gets both methods.
        let two = Shard { k: 1, n: 2 };
        assert_eq!((0..4).filter(|&i| two.owns(i)).collect::<Vec<_>>(), [0, 3]);
    }

    #[test]
    fn shards_parse_and_refuse_what_is_not_k_of_n() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { k: 2, n: 3 }));
        assert_eq!(" 1 / 1".parse::<Shard>(), Ok(Shard { k: 1, n: 1 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains("K/N"), "{bad}: {e}");
        }
    }
}
