//! A bitmap backend that places glyphs where the font says.
//!
//! Written by hand because no crate does it: plotters 0.3.7 rasterises text through ab_glyph but
//! draws every glyph's bitmap at the pen position, dropping the glyph's left side bearing, so
//! narrow glyphs ('.', 'i', 'l') sit at the left of their advance box and tick labels read "0 .4".
//! [`Glyphs`] wraps any backend, passes every call through, and draws text itself: each glyph
//! outlined at its pen position (advances and kerning as plotters lays them out, so the text
//! boxes plotters measures are unchanged) and its coverage blended pixel by pixel.

use ab_glyph::{Font, FontRef, ScaleFont, point};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind, text_anchor::HPos, text_anchor::VPos,
};

/// `inner` with text drawn from `font` (the one font the figures register).
pub(crate) struct Glyphs<B> {
    inner: B,
    font: FontRef<'static>,
}

impl<B: DrawingBackend> Glyphs<B> {
    pub fn new(inner: B, font_bytes: &'static [u8]) -> anyhow::Result<Self> {
        let font = FontRef::try_from_slice(font_bytes).map_err(|e| anyhow::anyhow!("the bundled font cannot be read: {e}"))?;
        Ok(Glyphs { inner, font })
    }

    /// The pixels of `text` at size `px`, relative to the pen's start on the line's top (the
    /// same vertical convention as plotters: the baseline at `px / 2` below the glyphs' tops).
    fn coverage(&self, text: &str, px: f32, mut put: impl FnMut(i32, i32, f32)) {
        let font = self.font.as_scaled(px);
        let mut pen = 0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                pen += font.kern(p, id);
            }
            prev = Some(id);
            if let Some(outline) = font.outline_glyph(id.with_scale_and_position(px, point(pen, 0.0))) {
                let b = outline.px_bounds();
                let (x0, y0) = (b.min.x as i32, (px / 2.0 + b.min.y) as i32);
                outline.draw(|x, y, cov| put(x0 + x as i32, y0 + y as i32, cov));
            }
            pen += font.h_advance(id);
        }
    }
}

impl<B: DrawingBackend> DrawingBackend for Glyphs<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    /// Anchored and rotated as plotters' default does; the glyphs from [`Glyphs::coverage`].
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style.layout_box(text).map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let trans = style.transform();
        let (w, h) = self.get_size();
        let mut pixels = Vec::new();
        self.coverage(text, style.size() as f32, |x, y, cov| pixels.push((x, y, cov)));
        for (x, y, cov) in pixels {
            let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
            let (x, y) = (pos.0 + x, pos.1 + y);
            if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 && cov > 0.0 {
                self.inner.draw_pixel((x, y), BackendColor { alpha: color.alpha * f64::from(cov.min(1.0)), rgb: color.rgb })?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// The columns where ink starts, one per glyph of a text whose glyphs do not touch.
    fn ink_starts(buf: &[u8], (w, h): (u32, u32)) -> Vec<i32> {
        let inked = |x: u32| (0..h).any(|y| buf[3 * (y * w + x) as usize] < 200);
        (0..w).filter(|&x| inked(x) && (x == 0 || !inked(x - 1))).map(|x| x as i32).collect()
    }

    #[test]
    fn each_glyph_is_drawn_where_the_font_places_it() {
        super::super::register_font().unwrap();
        let (text, px) = ("0.4", 80.0f32);
        let size = (300u32, 120u32);
        let mut buf = vec![255u8; (3 * size.0 * size.1) as usize];
        {
            let backend = Glyphs::new(BitMapBackend::with_buffer(&mut buf, size), super::super::FONT_BYTES).unwrap();
            let root = backend.into_drawing_area();
            root.draw_text(text, &super::super::font::font(f64::from(px)), (20, 10)).unwrap();
            root.present().unwrap();
        }
        // where ab_glyph puts each glyph's ink: pen position (advances, kerning) plus bearing
        let font = FontRef::try_from_slice(super::super::FONT_BYTES).unwrap();
        let scaled = font.as_scaled(px);
        let (mut pen, mut expected) = (0f32, Vec::new());
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            let outline = scaled.outline_glyph(id.with_scale_and_position(px, point(pen, 0.0))).unwrap();
            expected.push(outline.px_bounds().min.x as i32);
            pen += scaled.h_advance(id);
        }
        let seen = ink_starts(&buf, size);
        assert_eq!(seen.len(), 3, "three separate glyphs in {seen:?}");
        for k in 1..3 {
            let (got, want) = (seen[k] - seen[0], expected[k] - expected[0]);
            assert!((got - want).abs() <= 1, "glyph {k} of {text:?} starts {got} px after the first, the font says {want}");
        }
    }
}
