#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod data;
mod draw;
mod error;
mod font;
mod model;
mod output;
mod raster;

pub use error::PlotError;
pub use model::{Marker, MarkerKind, Page, Panel, Series, Style};
pub use output::{render, render_png, render_svg};
