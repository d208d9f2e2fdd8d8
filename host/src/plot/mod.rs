//! Plots shared by every command: SVG figures built with [`svg`] (a document builder and a
//! table-to-picture [`svg::Frame`]) and rendered to PNG ([`svg_to_png`]).

pub mod axes;
mod png;
pub mod svg;

pub use png::{render_png, svg_to_png};
