//! The font every text of a PNG is drawn in, embedded: Noto Sans 1.04 (Apache-2.0) from
//! `ttf-noto-sans`, regular and bold. Registered once with plotters under the family the drawing
//! code names, for its text layout.

use std::sync::OnceLock;

use ab_glyph::FontRef;
use plotters::style::FontStyle;

use crate::PlotError;

/// The font family every text of a plot is set in (SVG viewers use their own sans-serif).
pub(crate) const FAMILY: &str = "sans-serif";

/// The embedded faces.
pub(crate) struct Faces {
    pub(crate) regular: FontRef<'static>,
    pub(crate) bold: FontRef<'static>,
}

/// The embedded faces, parsed and registered with plotters on the first call.
pub(crate) fn faces() -> Result<&'static Faces, PlotError> {
    static FACES: OnceLock<Result<Faces, &'static str>> = OnceLock::new();
    let faces = FACES.get_or_init(|| {
        let regular = FontRef::try_from_slice(ttf_noto_sans::REGULAR).map_err(|_| "Noto Sans Regular")?;
        let bold = FontRef::try_from_slice(ttf_noto_sans::BOLD).map_err(|_| "Noto Sans Bold")?;
        plotters::style::register_font(FAMILY, FontStyle::Normal, ttf_noto_sans::REGULAR)
            .map_err(|_| "Noto Sans Regular")?;
        plotters::style::register_font(FAMILY, FontStyle::Bold, ttf_noto_sans::BOLD).map_err(|_| "Noto Sans Bold")?;
        Ok(Faces { regular, bold })
    });
    faces.as_ref().map_err(|font| PlotError::Backend(format!("the embedded font {font} does not parse").into()))
}
