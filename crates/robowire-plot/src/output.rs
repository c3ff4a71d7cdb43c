//! The image: checked input, SVG text or PNG bytes, a file by its extension.

use std::path::Path;

use plotters::drawing::DrawingAreaErrorKind;
use plotters::prelude::{IntoDrawingArea, SVGBackend};

use crate::draw::{WIDTH_PX, draw_pages, page_height_px};
use crate::raster::Raster;
use crate::{Page, PlotError, font};

/// The tallest image rendered (about 120 panels).
const MAX_HEIGHT_PX: u32 = 32_000;

/// Renders `pages` to `out`, as SVG or PNG by its extension (`.svg`, `.png`, any case).
///
/// The pages stand one under the other in one image 1200 px wide, each with its title and
/// its panels (about 260 px each) over one time axis, `time (s)`. Points with a coordinate that
/// is not finite (or beyond ±1e300) are skipped; dense series are drawn through each pixel
/// column's lowest and highest point.
pub fn render(pages: &[Page], out: &Path) -> Result<(), PlotError> {
    let extension = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let bytes = match extension.as_deref() {
        Some("svg") => render_svg(pages)?.into_bytes(),
        Some("png") => render_png(pages)?,
        _ => return Err(PlotError::UnknownExtension { path: out.to_owned() }),
    };
    std::fs::write(out, bytes).map_err(|source| PlotError::Write { path: out.to_owned(), source })
}

/// `pages` as an SVG document (text as `<text>`, set in the viewer's sans-serif).
pub fn render_svg(pages: &[Page]) -> Result<String, PlotError> {
    let height = image_height_px(pages)?;
    font::faces()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH_PX, height)).into_drawing_area();
        draw_pages(&root, pages).map_err(backend)?;
        root.present().map_err(backend)?;
    }
    Ok(svg)
}

/// `pages` as a PNG image (8-bit RGB, text in the embedded Noto Sans).
pub fn render_png(pages: &[Page]) -> Result<Vec<u8>, PlotError> {
    let height = image_height_px(pages)?;
    let faces = font::faces()?;
    let mut rgb = vec![0_u8; WIDTH_PX as usize * height as usize * 3];
    {
        let root = Raster::new(&mut rgb, (WIDTH_PX, height), faces).into_drawing_area();
        draw_pages(&root, pages).map_err(backend)?;
        root.present().map_err(backend)?;
    }
    let mut png = Vec::new();
    let mut encoder = png::Encoder::new(&mut png, WIDTH_PX, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(PlotError::Png)?;
    writer.write_image_data(&rgb).map_err(PlotError::Png)?;
    writer.finish().map_err(PlotError::Png)?;
    Ok(png)
}

/// The image's height for `pages`, once they are known to make an image.
fn image_height_px(pages: &[Page]) -> Result<u32, PlotError> {
    if pages.is_empty() {
        return Err(PlotError::NoPages);
    }
    if let Some((index, page)) = pages.iter().enumerate().find(|(_, p)| p.panels.is_empty()) {
        return Err(PlotError::EmptyPage { index, title: page.title.clone() });
    }
    let height: u64 = pages.iter().map(page_height_px).sum();
    u32::try_from(height).ok().filter(|&h| h <= MAX_HEIGHT_PX).ok_or_else(|| PlotError::TooLarge {
        panels: pages.iter().map(|p| p.panels.len()).sum(),
        height_px: u32::try_from(height).unwrap_or(u32::MAX),
        max_px: MAX_HEIGHT_PX,
    })
}

fn backend<E: std::error::Error + Send + Sync + 'static>(error: DrawingAreaErrorKind<E>) -> PlotError {
    PlotError::Backend(Box::new(error))
}
