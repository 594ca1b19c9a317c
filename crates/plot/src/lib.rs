//! # flexstar-plot
//!
//! The figure kit every flexstar crate draws with (plotters, SVG and PNG): curves ([`Series`]) in
//! panels ([`Panel`]) under a title and one legend strip ([`Figure`], [`GridFigure`]), the
//! [`Drawing`] trait for figures drawn by hand (heat maps, scatter plots), SVG and PNG writing
//! ([`svg_string`], [`write_svg_png`]) with the bundled font ([`register_font`]), tick labels
//! ([`tick`]), line styles and colours ([`Style`], [`colormap`]). It knows nothing of the robot:
//! the figures of a response live with their data (`flexstar-compare`, `flexstar-modal`,
//! `flexstar-study`).

pub mod drawing;
pub mod figure;
pub mod legend;
pub mod panel;
pub mod style;

pub use drawing::{register_font, svg_string, write_svg_png, Drawing, FigureError};
pub use figure::{legend_rows, Figure, GridFigure, Panel, RenderedFigure, Series, Zoom};
pub use legend::draw_legend;
pub use panel::{axis_ticks, min_max_thin, tick};
pub use style::{colormap, Style, EXTRA_COLORS, FAMILY_COLORS, FEM_STYLE, MARK_STYLE, RIGID_STYLE};
