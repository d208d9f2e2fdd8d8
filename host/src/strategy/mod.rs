//! The learned pushing strategy of Lau, Mitani & Igarashi ("Automatic Learning of Pushing
//! Strategy for Delivery of Irregular-Shaped Objects"), and the dipole-field baseline they
//! compare against (Igarashi, Kamiyama & Inami, ICRA 2010).
//!
//! - [`sample`]: one push as the paper's sample (p_x, p_y, r_x, r_y, s_x, s_y, θ) in the
//!   object's frame (§III-B, Fig. 2).
//! - [`store`]: the pushing strategy on disk, versioned, appended and flushed sample by sample.
//! - [`regression`]: k-nearest-neighbour kernel regression of Algorithm 2 (§III-E), general
//!   and special case, on k-d trees.
//! - [`active`]: choosing the next push where the strategy is least sure (active selection).
//! - [`dipole`]: the dipole field used as the baseline in §V (Fig. 10–11).
//!
//! The loops that act — collection (Algorithm 1) and delivery (Algorithm 2) — are executors in
//! [`crate::exec`]; the global path among obstacles is [`crate::planner::global`].

pub mod active;
pub mod bench;
pub mod dipole;
pub mod figures;
pub mod regression;

pub mod sample;
pub mod store;
