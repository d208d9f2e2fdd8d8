//! The learned pushing strategy of Lau, Mitani & Igarashi ("Automatic Learning of Pushing
//! Strategy for Delivery of Irregular-Shaped Objects"), and the dipole-field baseline they
//! compare against (Igarashi, Kamiyama & Inami, ICRA 2010).
//!
//! - [`sample`]: one push as the paper's sample (p_x, p_y, r_x, r_y, s_x, s_y, θ) in the
//!   object's frame (§III-B, Fig. 2).
//! - [`store`]: the pushing strategy on disk, versioned, appended and flushed sample by sample.
//! - [`regression`]: k-nearest-neighbour kernel regression of Algorithm 2 (§III-E), general
//!   and special case, on k-d trees.
//! - [`dipole`]: the dipole field used as the baseline in §V (Fig. 10–11).
//! - [`obstacles`]: a global path among obstacles followed through sub-goals (§III-E), and
//!   "collect (or reuse) then deliver" for a scene.

pub mod bench;
pub mod collect;
pub mod deliver;
pub mod dipole;
pub mod eval;
pub mod figures;
pub mod obstacles;
pub mod regression;
pub mod robot_io;
pub mod sample;
pub mod store;
