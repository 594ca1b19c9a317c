//! The shaper's sensitivity figure of `compare` (`docs/motions.md` 3.6): the residual amplitude
//! of a mode after the shaped motion, relative to the unshaped one (Singer and Seering's
//! percentage residual vibration, section 3.2, [`flexstar_model::shaper::residual`]), against the
//! mode's frequency, with the accurate AMM's modes at the final pose marked.

use flexstar_model::trajectory::ShapedMotion;
use flexstar_model::{Experiment, ModeFamily, Response, ShaperSection, Trajectory};
use flexstar_plot::{Figure, Panel, Series, Style, FAMILY_COLORS, FEM_STYLE, RIGID_STYLE};
use rayon::prelude::*;

use crate::Error;

/// Elastic modes of the accurate AMM looked at (those inside the plotted band are drawn).
const MODES: usize = 12;
/// Points of the curve.
const SAMPLES: usize = 400;
/// Frequency errors `e` of the measured points: every shaper frequency scaled by `1 + e`.
const ERRORS: [f64; 7] = [-0.3, -0.2, -0.1, 0.0, 0.1, 0.2, 0.3];

/// The figure `<name>-sensitivity` for an experiment with a resolved `[shaper]` (`None`
/// without one): `100 V(f, zeta(f))` [%] over `f` in `[0.5 f_min, 1.5 f_max]` of the shaper's
/// frequencies, `zeta(f)` the model's damping ratio of a mode at f (`[damping]`, else 0), and a
/// vertical line at each mode of the accurate AMM at the final pose (sliders locked) in the band.
pub fn figure_sensitivity(exp: &Experiment) -> Result<Option<Figure>, Error> {
    let Some(sh) = exp.shaper.as_ref().filter(|s| !s.frequencies_hz.is_empty()) else {
        return Ok(None);
    };
    let modes = flexstar_modal::analysis::final_pose_frequencies(exp, MODES)
        .map_err(|e| Error::Input {
            file: exp.source.display().to_string(),
            reason: format!("shaper sensitivity figure: modes at the final pose: {e}"),
        })?
        .unwrap_or_default();
    let (lo, hi) = band(&sh.frequencies_hz);
    let v = |f: f64| 100.0 * flexstar_model::shaper::residual(&sh.impulses, f, exp.damping.zeta_at(f));
    let x: Vec<f64> = (0..=SAMPLES)
        .map(|k| lo + (hi - lo) * k as f64 / SAMPLES as f64)
        .collect();
    let curve = Series {
        label: format!("{} shaper", format!("{:?}", sh.kind).to_uppercase()),
        y: x.iter().map(|&f| v(f)).collect(),
        x,
        style: Style {
            color: FAMILY_COLORS[0],
            width: 2,
            dashed: false,
        },
    };
    let mut series = vec![curve];
    series.extend(mode_lines(&modes, lo, hi));
    let measured = measured_points(exp, sh)?;
    let mut panels = vec![Panel {
        title: format!("(a) designed at {} Hz", list(&sh.frequencies_hz)),
        x_label: "mode frequency f [Hz]".into(),
        y_label: "residual / unshaped [%]".into(),
        series,
        equal_axes: false,
        min_y_span: 1.0,
    }];
    panels.extend(error_panel(&measured, &modes, lo, hi, sh));
    Ok(Some(Figure {
        zooms: Vec::new(),
        name: format!("{}-sensitivity", exp.name),
        title: format!("{}: shaper sensitivity (residual vs mode frequency)", exp.name),
        caption: caption(&sh.frequencies_hz, &modes, lo, hi, &v) + &measured_caption(&measured),
        panels,
    }))
}

/// The plotted band `[0.5 f_min, 1.5 f_max]` [Hz].
fn band(f: &[f64]) -> (f64, f64) {
    let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = f.iter().copied().fold(0.0, f64::max);
    (0.5 * lo, 1.5 * hi)
}

/// One vertical line (0 to 100 %) per AMM mode inside `[lo, hi]`, labelled once.
fn mode_lines(modes: &[f64], lo: f64, hi: f64) -> Vec<Series> {
    modes
        .iter()
        .filter(|f| (lo..=hi).contains(*f))
        .enumerate()
        .map(|(j, &f)| Series {
            label: if j == 0 {
                "AMM modes, final pose".into()
            } else {
                String::new()
            },
            x: vec![f, f],
            y: vec![0.0, 100.0],
            style: RIGID_STYLE,
        })
        .collect()
}

/// The caption: what the curve is, and the predicted residual factor at each marked mode.
fn caption(design: &[f64], modes: &[f64], lo: f64, hi: f64, v: &dyn Fn(f64) -> f64) -> String {
    let at: Vec<String> = modes
        .iter()
        .filter(|f| (lo..=hi).contains(*f))
        .map(|&f| format!("{f:.3} Hz: {:.1} %", v(f)))
        .collect();
    format!(
        "The shaper's sensitivity curve (docs/motions.md 3.2): the residual amplitude of a mode of frequency f \
         after the shaped motion, relative to the unshaped motion's, from the shaper's impulses (designed at {} Hz; \
         damping from [damping], else 0). Computed with the AMM: the grey vertical lines are the modes of the \
         accurate AMM (enriched family) at the motion's final pose, sliders locked; the curve's value there is the \
         LTI prediction of how much of each mode's residual is left ({}). A mode near a zero of the curve is \
         cancelled; a frequency error moves it along the curve.",
        list(design),
        if at.is_empty() {
            "no mode in the band".to_string()
        } else {
            at.join("; ")
        }
    )
}

/// Frequencies as `3.950, 6.812`.
fn list(f: &[f64]) -> String {
    f.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(", ")
}

/// The peak of `|dG| = sqrt(2/3 sum_i w_iG^2)` [m] (the elastic displacement of G in the fixed
/// frame from its three rigid-frame components, docs/motions.md section 2) at `t >= t_rest`,
/// about the rest pose's static equilibrium under gravity (`Response::w_g_about_rest`).
fn residual_peak(r: &Response, t_rest: f64) -> f64 {
    (0..r.t.len())
        .filter(|&k| r.t[k] >= t_rest - 1e-12)
        .map(|k| flexstar_metrics::residual::dg_magnitude([0, 1, 2].map(|i| r.w_g_about_rest(i, k))))
        .fold(0.0, f64::max)
}

/// The AMM's measured residual ratios `(e, peak_e / peak_unshaped)` (docs/motions.md 3.6): the
/// base motion unshaped, and shaped with every frequency scaled by `1 + e` for `e` in [`ERRORS`]
/// (those whose shaped motion rests before `t_end`), each with the experiment's `[amm]` settings
/// in the enriched family, residual peak of |dG| after each run's own `t_rest`.
fn measured_points(exp: &Experiment, sh: &ShaperSection) -> Result<Vec<(f64, f64)>, Error> {
    let Trajectory::Shaped(shaped) = &exp.trajectory else {
        return Ok(Vec::new());
    };
    let base = shaped.base.as_ref();
    let Some(t0) = base.t_rest() else {
        return Ok(Vec::new());
    };
    let mut jobs: Vec<(Option<f64>, Experiment, f64)> = vec![(None, with_motion(exp, base.clone()), t0)];
    for e in ERRORS {
        let mut sec = sh.clone();
        let scaled: Vec<f64> = sh.frequencies_hz.iter().map(|f| f * (1.0 + e)).collect();
        sec.resolve(&scaled, |f| exp.damping.zeta_at(f))?;
        if t0 + sec.penalty_s < exp.time.t_end - 0.05 {
            let motion = Trajectory::Shaped(ShapedMotion {
                base: Box::new(base.clone()),
                impulses: sec.impulses.clone(),
            });
            jobs.push((Some(e), with_motion(exp, motion), t0 + sec.penalty_s));
        }
    }
    let settings = flexstar_model::AmmSettings {
        family: ModeFamily::Enriched,
        snapshots: Vec::new(),
        ..exp.amm.clone()
    };
    let peaks: Vec<f64> = jobs
        .par_iter()
        .map(|(_, x, t_rest)| {
            let problem = x.problem().map_err(flexstar_solve::SolveError::from)?;
            flexstar_solve::response(&problem, flexstar_solve::Settings::Amm(&settings), None, None)
                .map(|r| residual_peak(&r, *t_rest))
        })
        .collect::<Result<_, _>>()
        .map_err(|e| Error::Input {
            file: exp.source.display().to_string(),
            reason: format!("shaper sensitivity figure: AMM run: {e}"),
        })?;
    let p0 = peaks[0].max(1e-300);
    Ok(jobs
        .iter()
        .zip(&peaks)
        .filter_map(|((e, _, _), p)| e.map(|e| (e, p / p0)))
        .collect())
}

/// The experiment with another motion and no shaper section (the runs of [`measured_points`]).
fn with_motion(exp: &Experiment, motion: Trajectory) -> Experiment {
    let mut x = exp.clone();
    x.trajectory = motion;
    x.shaper = None;
    x
}

/// Panel (b): the measured AMM ratios against the frequency error `e` [%], over the formula's
/// residual of each AMM mode in the band (`V(f_k)` of the shaper designed at `f (1 + e)`).
fn error_panel(measured: &[(f64, f64)], modes: &[f64], lo: f64, hi: f64, sh: &ShaperSection) -> Option<Panel> {
    if measured.is_empty() {
        return None;
    }
    let es: Vec<f64> = (0..=120).map(|k| -0.3 + 0.6 * k as f64 / 120.0).collect();
    let mut series: Vec<Series> = modes
        .iter()
        .filter(|f| (lo..=hi).contains(*f))
        .enumerate()
        .map(|(j, &f)| Series {
            label: if j == 0 {
                "formula at each AMM mode".into()
            } else {
                String::new()
            },
            x: es.iter().map(|e| 100.0 * e).collect(),
            y: es.iter().map(|&e| 100.0 * scaled_residual(sh, e, f)).collect(),
            style: RIGID_STYLE,
        })
        .collect();
    series.push(Series {
        label: "AMM runs: residual peak of G".into(),
        x: measured.iter().map(|p| 100.0 * p.0).collect(),
        y: measured.iter().map(|p| 100.0 * p.1).collect(),
        style: FEM_STYLE,
    });
    Some(Panel {
        title: "(b) every shaper frequency scaled by 1 + e".into(),
        x_label: "frequency error e [%]".into(),
        y_label: "residual / unshaped [%]".into(),
        series,
        equal_axes: false,
        min_y_span: 1.0,
    })
}

/// The formula's residual of a mode at `f` [Hz] after the shaper designed at the section's
/// frequencies scaled by `1 + e` (undamped: the design's zeta list is kept, default 0).
fn scaled_residual(sh: &ShaperSection, e: f64, f: f64) -> f64 {
    let mut sec = sh.clone();
    let scaled: Vec<f64> = sh.frequencies_hz.iter().map(|x| x * (1.0 + e)).collect();
    match sec.resolve(&scaled, |_| 0.0) {
        Ok(()) => flexstar_model::shaper::residual(&sec.impulses, f, 0.0),
        Err(_) => f64::NAN,
    }
}

/// The caption's sentence on panel (b).
fn measured_caption(measured: &[(f64, f64)]) -> String {
    if measured.is_empty() {
        return String::new();
    }
    let pts: Vec<String> = measured
        .iter()
        .map(|(e, r)| format!("{:+.0} %: {:.1} %", 100.0 * e, 100.0 * r))
        .collect();
    format!(
        " (b) Measured with the AMM (enriched family, the experiment's [amm] settings): the motion shaped with every \
         shaper frequency scaled by 1 + e, its residual peak of |dG| after its own t_rest divided by the unshaped \
         motion's (black; e: ratio = {}), over the formula's residual of each AMM mode of (a) (grey dashed); the \
         distance between them is what the LTI formula does not see (the pose changes during the move, several \
         modes add up).",
        pts.join(", ")
    )
}
