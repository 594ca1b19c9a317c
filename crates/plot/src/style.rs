//! Line styles and colours shared by every figure: the FEM black, the rigid grey, one colour per
//! mode family, and a viridis-like colour map for heat maps.

use plotters::style::RGBColor;

/// Line style of a curve: colour index and dash.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    pub color: RGBColor,
    pub width: u32,
    pub dashed: bool,
}

/// Viridis-like colour of `u` in [0, 1] (five anchors of matplotlib's viridis, linearly blended);
/// NaN maps to the dark end.
pub fn colormap(u: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let u = if u.is_finite() { u.clamp(0.0, 1.0) } else { 0.0 };
    let s = u * 4.0;
    let i = (s.floor() as usize).min(3);
    let f = s - i as f64;
    let (a, b) = (ANCHORS[i], ANCHORS[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Colours: FEM black, then one per AMM family, rigid grey.
pub const FEM_STYLE: Style = Style {
    color: RGBColor(0, 0, 0),
    width: 3,
    dashed: false,
};
pub const RIGID_STYLE: Style = Style {
    color: RGBColor(140, 140, 140),
    width: 1,
    dashed: true,
};
/// A time mark (the end of the motion, `t_rest`): thin dashed blue-grey.
pub const MARK_STYLE: Style = Style {
    color: RGBColor(90, 110, 170),
    width: 1,
    dashed: true,
};
/// One colour per mode family, in the order of `ModeFamily::ALL` (pinned-free red, slide-free
/// blue, free-free green, clamped-free purple, enriched orange), so that a family has the same
/// colour in every figure and report.
pub const FAMILY_COLORS: [RGBColor; 5] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];
/// Colours for further runs of a family already drawn (e.g. the same family at another N).
pub const EXTRA_COLORS: [RGBColor; 3] = [RGBColor(140, 86, 75), RGBColor(227, 119, 194), RGBColor(23, 190, 207)];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormap_ends_are_viridis_ends() {
        assert_eq!(colormap(0.0), RGBColor(68, 1, 84));
        assert_eq!(colormap(1.0), RGBColor(253, 231, 37));
        assert_eq!(colormap(f64::NAN), RGBColor(68, 1, 84));
    }
}
