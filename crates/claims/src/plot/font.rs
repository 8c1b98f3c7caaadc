//! The figures' font and drawing errors, shared by the figure layouts ([`super::render`]) and
//! the rich-text labels ([`super::rich`]).

use plotters::prelude::*;

/// The registered font: one name for ab_glyph and a CSS font list for the SVG viewer.
pub(crate) const FONT: &str = "DejaVu Sans, sans-serif";

pub(crate) fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FONT, size).into_font())
}

/// Map plotters' drawing errors (which are generic over the backend) to anyhow.
pub(crate) trait DrawResult<T> {
    fn drawn(self) -> anyhow::Result<T>;
}

impl<T, E: std::fmt::Display> DrawResult<T> for Result<T, E> {
    fn drawn(self) -> anyhow::Result<T> {
        self.map_err(|e| anyhow::anyhow!("drawing failed: {e}"))
    }
}
