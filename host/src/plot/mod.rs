//! Plots shared by every command: SVG figures rendered to PNG ([`svg_to_png`]).

mod png;

pub use png::{render_png, svg_to_png};
