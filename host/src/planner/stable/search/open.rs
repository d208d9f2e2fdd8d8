//! OPEN, the list of generated steps waiting to be expanded: the paper's array of FIFO lists
//! indexed by integer cost (Lynch & Mason 1996 §4.2.2), or a binary heap for cross-checking.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Which OPEN list to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Queue {
    /// The paper's array of first-in first-out lists indexed by integer cost (here `f = g + h`).
    Buckets,
    /// A binary heap ordered by `(f, insertion order)`; for cross-checking.
    Heap,
}

/// A generated step waiting in OPEN: control `control` of contact `contact` from the expanded
/// node `parent` (`NONE`: the start itself), reaching cost `cost`. Its end configuration is
/// recomputed from the parent when it is taken, with the same arithmetic, so bit for bit the
/// one tested when it was generated; OPEN holds 16 bytes per entry.
#[derive(Clone, Copy)]
pub(super) struct Pending {
    pub(super) parent: u32,
    pub(super) contact: u32,
    pub(super) control: u32,
    pub(super) cost: u32,
    /// A normal step, or one of the exact finishes.
    pub(super) finish: Finish,
}

/// How a node in OPEN reaches its configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Finish {
    /// The parent's step of `control` on `contact`.
    No,
    /// The parent's step only up to where it first enters the goal neighbourhood
    /// ([`super::crossing`]).
    Crossing,
    /// One usable push of `contact` from the parent straight onto the goal (§4.5's finish).
    Push,
}

/// One of the paper's FIFO lists: a vector read from `head` on.
#[derive(Clone, Default)]
pub(super) struct Fifo {
    items: Vec<Pending>,
    head: usize,
}

/// OPEN: the paper's cost-indexed FIFO lists, or one heap (ordered by `(f, insertion order)`
/// over a store of the entries).
pub(super) enum Open {
    Buckets {
        lists: Vec<Fifo>,
        cur: usize,
        /// Emptied lists' buffers, reused by lists that fill up (fewer page faults and copies).
        spare: Vec<Vec<Pending>>,
    },
    Heap {
        heap: BinaryHeap<Reverse<(u32, u32)>>,
        store: Vec<Pending>,
    },
}

impl Open {
    /// Add `n` with priority `f`.
    pub(super) fn push(&mut self, f: u32, n: Pending) {
        match self {
            Open::Buckets { lists, cur, spare } => {
                let f = f as usize;
                if let Some(l) = lists.get_mut(f) {
                    if l.items.capacity() == 0
                        && let Some(v) = spare.pop()
                    {
                        l.items = v;
                    }
                    l.items.push(n);
                    *cur = (*cur).min(f);
                }
            }
            Open::Heap { heap, store } => {
                heap.push(Reverse((f, store.len() as u32)));
                store.push(n);
            }
        }
    }

    /// Take the entry of least priority (first in among equals).
    pub(super) fn pop(&mut self) -> Option<Pending> {
        match self {
            Open::Buckets { lists, cur, spare } => {
                while let Some(l) = lists.get_mut(*cur) {
                    if let Some(&n) = l.items.get(l.head) {
                        l.head += 1;
                        if l.head == l.items.len() {
                            // Drained: keep its buffer for another list.
                            let mut v = std::mem::take(&mut l.items);
                            l.head = 0;
                            v.clear();
                            spare.push(v);
                        }
                        return Some(n);
                    }
                    *cur += 1;
                }
                None
            }
            Open::Heap { heap, store } => heap.pop().map(|Reverse((_, i))| store[i as usize]),
        }
    }
}
