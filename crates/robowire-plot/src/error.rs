//! What can go wrong rendering.

use std::path::PathBuf;

/// Why nothing (or not all of it) was rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The output's extension is neither `.svg` nor `.png`.
    #[error("{path}: unknown image format (the file name must end in .svg or .png)")]
    UnknownExtension {
        /// The output path given.
        path: PathBuf,
    },
    /// There is no page to render.
    #[error("nothing to plot: no page")]
    NoPages,
    /// A page has no panel.
    #[error("page {index} ({title:?}) has no panel")]
    EmptyPage {
        /// The page's index in the input, from 0.
        index: usize,
        /// The page's title.
        title: String,
    },
    /// The pages together are taller than an image may be.
    #[error("{panels} panels make an image {height_px} px tall, over the limit of {max_px} px")]
    TooLarge {
        /// The panels of all pages.
        panels: usize,
        /// The image's height they need.
        height_px: u32,
        /// The tallest image rendered.
        max_px: u32,
    },
    /// The plotting library failed to draw.
    #[error("drawing the plot")]
    Backend(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// The pixels could not be encoded as PNG.
    #[error("encoding the PNG")]
    Png(#[source] png::EncodingError),
    /// The image could not be written.
    #[error("writing {path}")]
    Write {
        /// The output path.
        path: PathBuf,
        /// Why the write failed.
        #[source]
        source: std::io::Error,
    },
}
