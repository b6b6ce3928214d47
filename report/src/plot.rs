//! A small log–log line plot rendered to RGB pixels, with a built-in 5×7 bitmap font, so
//! that reports need no plotting library or system fonts.

/// One curve.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points `(x, y)`, both positive.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub color: [u8; 3],
    /// Dashed line.
    pub dashed: bool,
}

/// A distinct colour for series `i`.
pub fn palette(i: usize) -> [u8; 3] {
    const P: [[u8; 3]; 10] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [127, 127, 127],
        [188, 189, 34],
        [23, 190, 207],
    ];
    P[i % P.len()]
}

/// An RGB canvas.
pub struct Canvas {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Row-major RGB.
    pub rgb: Vec<u8>,
}

impl Canvas {
    fn new(width: u32, height: u32) -> Self {
        Self { width, height, rgb: vec![255; (3 * width * height) as usize] }
    }

    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    fn rect(&mut self, x0: i64, y0: i64, w: i64, h: i64, c: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.set(x, y, c);
            }
        }
    }

    fn line(&mut self, (x0, y0): (f64, f64), (x1, y1): (f64, f64), c: [u8; 3], width: i64, dashed: bool) {
        let steps = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as i64).max(1);
        for s in 0..=steps {
            if dashed && (s / 6) % 2 == 1 {
                continue;
            }
            let t = s as f64 / steps as f64;
            let (x, y) = (x0 + t * (x1 - x0), y0 + t * (y1 - y0));
            self.rect(x.round() as i64 - width / 2, y.round() as i64 - width / 2, width, width, c);
        }
    }

    /// Draws `text` with its top-left corner at `(x, y)`, `scale` pixels per font pixel.
    pub fn text(&mut self, x: i64, y: i64, text: &str, c: [u8; 3], scale: i64) {
        for (k, ch) in text.chars().enumerate() {
            let g = glyph(ch);
            for (row, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        self.rect(x + (k as i64 * 6 + col) * scale, y + row as i64 * scale, scale, scale, c);
                    }
                }
            }
        }
    }
}

/// Width in pixels of `text` drawn at `scale`.
pub fn text_width(text: &str, scale: i64) -> i64 {
    text.chars().count() as i64 * 6 * scale
}

/// A log–log plot of `series` on a `width`×`height` canvas.
pub fn log_log(title: &str, x_label: &str, y_label: &str, series: &[Series], width: u32, height: u32) -> Canvas {
    let mut c = Canvas::new(width, height);
    let legend_w = 20 + series.iter().map(|s| text_width(&s.label, 1)).max().unwrap_or(0) as u32 + 30;
    let (left, right, top, bottom) = (80i64, (width - legend_w.min(width / 2)) as i64, 40i64, (height - 60) as i64);
    let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.iter().copied()).filter(|p| p.0 > 0.0 && p.1 > 0.0).collect();
    let black = [0, 0, 0];
    let grey = [225, 225, 225];
    c.text((width as i64 - text_width(title, 2)) / 2, 10, title, black, 2);
    if all.is_empty() {
        return c;
    }
    let dec = |v: f64| v.log10();
    let (mut x0, mut x1) = all.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(dec(p.0)), b.max(dec(p.0))));
    let (mut y0, mut y1) = all.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(dec(p.1)), b.max(dec(p.1))));
    (x0, x1) = (x0.floor(), x1.ceil().max(x0.floor() + 1.0));
    (y0, y1) = (y0.floor(), y1.ceil().max(y0.floor() + 1.0));
    let px = |x: f64| left as f64 + (dec(x) - x0) / (x1 - x0) * (right - left) as f64;
    let py = |y: f64| bottom as f64 - (dec(y) - y0) / (y1 - y0) * (bottom - top) as f64;
    // Decade grid and labels.
    for d in x0 as i64..=x1 as i64 {
        let x = px(10f64.powi(d as i32)).round() as i64;
        c.rect(x, top, 1, bottom - top, grey);
        let label = format!("1E{d}");
        c.text(x - text_width(&label, 1) / 2, bottom + 6, &label, black, 1);
    }
    for d in y0 as i64..=y1 as i64 {
        let y = py(10f64.powi(d as i32)).round() as i64;
        c.rect(left, y, right - left, 1, grey);
        let label = format!("1E{d}");
        c.text(left - 6 - text_width(&label, 1), y - 3, &label, black, 1);
    }
    c.rect(left, top, 1, bottom - top, black);
    c.rect(left, bottom, right - left, 1, black);
    c.text((left + right) / 2 - text_width(x_label, 1) / 2, bottom + 24, x_label, black, 1);
    c.text(4, top - 14, y_label, black, 1);
    for s in series {
        let pts: Vec<(f64, f64)> = s.points.iter().filter(|p| p.0 > 0.0 && p.1 > 0.0).map(|&(x, y)| (px(x), py(y))).collect();
        for w in pts.windows(2) {
            c.line(w[0], w[1], s.color, 2, s.dashed);
        }
        for p in &pts {
            c.rect(p.0.round() as i64 - 3, p.1.round() as i64 - 3, 7, 7, s.color);
        }
    }
    // Legend.
    for (k, s) in series.iter().enumerate() {
        let y = top + 4 + 14 * k as i64;
        c.line(((right + 12) as f64, (y + 3) as f64), ((right + 30) as f64, (y + 3) as f64), s.color, 3, s.dashed);
        c.text(right + 36, y, &s.label, black, 1);
    }
    c
}

/// The 5×7 glyph of `ch` (lower case drawn as upper case; unknown characters blank).
fn glyph(ch: char) -> [u8; 7] {
    match ch.to_ascii_uppercase() {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        'A' => [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C],
        '-' => [0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00],
        '+' => [0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '/' => [0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00],
        ':' => [0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        ',' => [0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08],
        '=' => [0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00],
        '_' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F],
        '^' => [0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00],
        '>' => [0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08],
        '<' => [0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02],
        '×' => [0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x00],
        _ => [0; 7],
    }
}
