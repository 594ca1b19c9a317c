//! Forward sensitivities of an AMM run along changes of its motion or of its physical
//! parameters (`docs/amm.md` 2.2, Eqs. T-1 to T-4): the tangent-linear model of the
//! generalized-alpha step, solved with each step's own factors.
//!
//! A direction is the same problem moved by `eps` along it: its motion (a via point or a timing
//! variable of a plan, a coefficient of a polynomial motion) or a physical parameter that keeps
//! the mode basis (a modulus, a density, the payload, the damping, the load: `docs/amm.md` 2.2,
//! "Physical parameters"). Per step and direction, the step's equations are evaluated once more
//! on a copy of the system (the probe; one built at the moved parameters where the direction
//! moves them): at the direction's rigid state, the predictors and lagged accelerations moved by
//! `eps` times their tangents, and the step's own solution (`q''`, multipliers). That residual,
//! less the step's own (zero to round-off), is `eps` times the directional derivative of the
//! equations; one solve with the step's factors turns it into `eps` times the tangent of `q''`
//! (internal numerical differentiation: the derivative of the discrete step, not of a second
//! run). The update and the predictor are linear and act on the tangents as on the state. The
//! outputs' tangents (the junction and tips, Eq. 33's forces, the sensors' readings) are their
//! values at the moved state less the run's, over `eps`.
//!
//! Cost per step and direction: the probe's sleeve rows, arrowhead and forcing, two residual
//! passes and one substitution with the step's factors; no factorisation.

use flexstar_model::{AmmSettings, ModeCount, Problem, Response, SensorTable};
use flexstar_numerics::GenAlpha;

use crate::error::AmmError;
use crate::modes::dot;
use crate::record::SliderForce;
use crate::sensors::SensorRecorder;
use crate::solver::{build_system, integrate_system, validate, Step, StepObserver, RHO_INF};
use crate::star::Star;
use crate::system::System;

/// An AMM run with the derivatives of its outputs along directions of its motion or parameters.
#[derive(Debug, Clone)]
pub struct Sensitivities {
    /// The run itself, as [`crate::solve`] gives it at the same fixed N and step.
    pub response: Response,
    /// Per direction and beam, `d w_iG / d p` at every output row [m per unit of p]: the
    /// direction's change of the junction's elastic displacement (the `w_iG` columns of the
    /// response) over its `eps`.
    pub w_g: Vec<[Vec<f64>; 3]>,
    /// Per direction and beam, `d w_i(L) / d p` at every output row, likewise.
    pub w_tip: Vec<[Vec<f64>; 3]>,
    /// Per direction and slider, `d Fa_i / d p` at every output row [N per unit of p]: the
    /// actuator force of Eq. 33 (the `fa` columns of the response), from the tangents of the
    /// multipliers, the sleeve rotation and the rigid state.
    pub fa: Vec<[Vec<f64>; 3]>,
    /// Per direction, the derivatives of the sensors' readings at the output times (the
    /// columns of `response.sensors`, before the data acquisition: `docs/sensors.md` section 6)
    /// [the sensor's unit per unit of p]; `None` without sensors.
    pub sensors: Option<Vec<SensorTable>>,
}

/// The run of `problem` at the fixed N of `settings.modes` and the derivatives of its outputs
/// along each of `moved`: direction k is the problem moved by `eps[k]` along it, in its motion
/// or in physical parameters that keep the mode basis (every beam's length and sleeve length;
/// the same output times, sensors and everything else). The derivative is that of the discrete
/// run (the tangent-linear model, module docs), so it matches central differences of whole runs
/// to the order of their own truncation error.
///
/// Refused before any work: what [`sensitivities_cover`] refuses (of the problem or of a moved
/// one), moved problems with other output times, sensors or mode basis, and a step `eps[k]`
/// that is zero or not finite.
pub fn solve_with_sensitivities(
    problem: &Problem,
    settings: &AmmSettings,
    moved: &[Problem],
    eps: &[f64],
) -> Result<Sensitivities, AmmError> {
    let n = fixed_modes(settings)?;
    let star = Star::new(problem);
    if eps.len() != moved.len() || !eps.iter().all(|e| e.is_finite() && *e != 0.0) {
        return Err(AmmError::invalid(
            "eps",
            format!("need one finite nonzero step per direction, got {eps:?}"),
        ));
    }
    let stars: Vec<Star> = moved.iter().map(Star::new).collect();
    if stars.iter().any(|s| s.time.output_times() != star.time.output_times()) {
        return Err(AmmError::invalid(
            "time",
            "every moved problem needs the same output times",
        ));
    }
    if stars.iter().any(|s| s.sensors != star.sensors) {
        return Err(AmmError::invalid(
            "sensors",
            "every moved problem needs the same sensors",
        ));
    }
    if stars.iter().any(|s| !s.same_basis(&star)) {
        return Err(AmmError::invalid(
            "robot",
            "every moved problem needs the same mode basis: the same robot, or one whose beams and \
             sleeves keep their lengths (L, Lp)",
        ));
    }
    let started = std::time::Instant::now();
    let dt_max = validate(&star, settings, n, true)?;
    let mut sys = build_system(settings, n, &star)?;
    covered(&sys)?;
    let (probes, probe_of) = probes(&sys, settings, n, (&star, &stars))?;
    sys.keep_sleeve_values();
    let n_out = star.time.output_times().len();
    let sensors = SensorRecorder::new(star.sensors, &sys, star.gravity, n_out);
    let mut tangent = Tangent::new(&sys, &stars, (eps, probes, probe_of), (sensors, n_out));
    let response = integrate_system(&star, settings, sys, dt_max, started, &mut tangent)?;
    if let Some(e) = tangent.failed.take() {
        return Err(e);
    }
    Ok(Sensitivities {
        response,
        w_g: tangent.w_g,
        w_tip: tangent.w_tip,
        fa: tangent.fa,
        sensors: tangent.d_sensors,
    })
}

/// Whether [`solve_with_sensitivities`] covers `problem` at `settings`: a fixed N, and no
/// friction or gravity (their terms are not in the tangent yet: `docs/amm.md`
/// 2.2); the refusal otherwise, naming the key. Builds the system (cached), runs nothing.
pub fn sensitivities_cover(problem: &Problem, settings: &AmmSettings) -> Result<(), AmmError> {
    let n = fixed_modes(settings)?;
    covered(&build_system(settings, n, &Star::new(problem))?)
}

/// The fixed N of `settings`, or the refusal of an automatic one.
fn fixed_modes(settings: &AmmSettings) -> Result<usize, AmmError> {
    match settings.mode_count() {
        ModeCount::Fixed(n) => Ok(n),
        _ => Err(AmmError::invalid(
            "amm.modes",
            "sensitivities need a fixed N (amm.modes)",
        )),
    }
}

/// The refusal of a system whose equations are not all in the tangent's residual.
fn covered(sys: &System) -> Result<(), AmmError> {
    if sys.has_tangent() {
        Ok(())
    } else {
        Err(AmmError::invalid(
            "amm",
            "sensitivities are not built for friction or gravity",
        ))
    }
}

/// A copy of the system on which the step's equations are evaluated for some directions, with
/// Eq. 33's data of its robot.
struct Probe {
    sys: System,
    force: SliderForce,
}

/// The probes of the directions `stars` about the run's `sys` of `star`, and each direction's
/// probe: the first a copy of `sys` (every direction that moves the motion only), then one
/// system built at each other set of physical parameters. Those whose beams differ evaluate
/// their own sleeves' truncation flexibility (it depends on the beams' stiffness); every probe
/// takes the rest of the sleeve rows to first order about the run's (the same modes,
/// `sleeve::near`).
fn probes(
    sys: &System,
    settings: &AmmSettings,
    n: usize,
    (star, stars): (&Star, &[Star]),
) -> Result<(Vec<Probe>, Vec<usize>), AmmError> {
    let mut probes = vec![Probe {
        sys: sys.clone(),
        force: SliderForce::new(sys, settings.model, star),
    }];
    let mut owners: Vec<&Star> = vec![star];
    let mut probe_of = Vec::with_capacity(stars.len());
    for s in stars {
        if let Some(j) = owners.iter().position(|o| o.same_physics(s)) {
            probe_of.push(j);
            continue;
        }
        let mut moved = build_system(settings, n, s)?;
        covered(&moved)?;
        if s.beams != star.beams {
            moved.evaluate_own_flexibility();
        }
        let force = SliderForce::new(&moved, settings.model, s);
        probe_of.push(probes.len());
        probes.push(Probe { sys: moved, force });
        owners.push(s);
    }
    Ok((probes, probe_of))
}

/// One direction's tangent state (per unit of its parameter): coordinates, rates, the
/// generalized-alpha acceleration variable and the accelerations of the last step.
#[derive(Debug, Clone)]
struct Direction {
    dq: Vec<f64>,
    dv: Vec<f64>,
    dacc: Vec<f64>,
    dqdd: Vec<f64>,
}

/// The sensors' readings of the run and their tangents (`None` without sensors).
struct SensorTangents {
    reader: SensorRecorder,
    /// The run's readings at the step, and a direction's at its moved state.
    base: Vec<f64>,
    row: Vec<f64>,
    /// The moved rates and accelerations.
    v_moved: Vec<f64>,
    qdd_moved: Vec<f64>,
}

/// The observer of the run that carries the tangents (module docs).
struct Tangent<'a> {
    probes: Vec<Probe>,
    /// Each direction's probe.
    probe_of: Vec<usize>,
    /// The moved problems.
    moved: &'a [Star<'a>],
    /// Each direction's step.
    eps: &'a [f64],
    ga: GenAlpha,
    dirs: Vec<Direction>,
    /// The base's accelerations of the previous step (the lagged terms' input).
    qdd_prev: Vec<f64>,
    w_g: Vec<[Vec<f64>; 3]>,
    w_tip: Vec<[Vec<f64>; 3]>,
    fa: Vec<[Vec<f64>; 3]>,
    sensors: Option<SensorTangents>,
    d_sensors: Option<Vec<SensorTable>>,
    failed: Option<AmmError>,
    // workspaces
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    lagged: Vec<f64>,
    da: Vec<f64>,
    primal0: Vec<f64>,
    rows0: Vec<f64>,
    primal: Vec<f64>,
    rows: Vec<f64>,
    corr_q: Vec<f64>,
    corr_l: Vec<f64>,
    q_moved: Vec<f64>,
    lam_moved: Vec<f64>,
    nq: Vec<f64>,
    nv: Vec<f64>,
}

impl<'a> Tangent<'a> {
    /// The tangents of a run with `n_out` output rows, all zero at the start.
    fn new(
        sys: &System,
        moved: &'a [Star<'a>],
        (eps, probes, probe_of): (&'a [f64], Vec<Probe>, Vec<usize>),
        (sensors, n_out): (Option<SensorRecorder>, usize),
    ) -> Self {
        let n = 3 * sys.nb;
        let m = sys.rows.len();
        let zero = Direction {
            dq: vec![0.0; n],
            dv: vec![0.0; n],
            dacc: vec![0.0; n],
            dqdd: vec![0.0; n],
        };
        let column = || [vec![0.0; n_out], vec![0.0; n_out], vec![0.0; n_out]];
        let d_sensors = sensors
            .as_ref()
            .map(|s| (0..moved.len()).map(|_| s.empty_table(n_out)).collect());
        let sensors = sensors.map(|reader| SensorTangents {
            base: Vec::with_capacity(reader.width()),
            row: Vec::with_capacity(reader.width()),
            reader,
            v_moved: vec![0.0; n],
            qdd_moved: vec![0.0; n],
        });
        Tangent {
            probes,
            probe_of,
            moved,
            eps,
            ga: GenAlpha::new(RHO_INF),
            dirs: vec![zero; moved.len()],
            qdd_prev: vec![0.0; n],
            w_g: (0..moved.len()).map(|_| column()).collect(),
            w_tip: (0..moved.len()).map(|_| column()).collect(),
            fa: (0..moved.len()).map(|_| column()).collect(),
            sensors,
            d_sensors,
            failed: None,
            qhat: vec![0.0; n],
            vhat: vec![0.0; n],
            lagged: vec![0.0; n],
            da: vec![0.0; n],
            primal0: vec![0.0; n],
            rows0: vec![0.0; m],
            primal: vec![0.0; n],
            rows: vec![0.0; m],
            corr_q: vec![0.0; n],
            corr_l: vec![0.0; m],
            q_moved: vec![0.0; n],
            lam_moved: vec![0.0; m],
            nq: vec![0.0; n],
            nv: vec![0.0; n],
        }
    }

    /// Eqs. T-1 to T-4 for one step (or the start, `h = 0`) of every direction.
    fn advance(&mut self, sys: &mut System, step: &Step) -> Result<(), AmmError> {
        let Some((qhat, vhat)) = step.predicted else {
            return Err(AmmError::invalid("amm", "sensitivities are not built for friction"));
        };
        let (bp, h) = (step.bp, step.h);
        let gp = step.gp;
        // Eq. 33 at the step's own state, on an output row (the recorder's forces), and the
        // sensors' readings there
        let fa0 = step.output.map(|_| {
            let axial = sys.sleeves.axial();
            [0, 1, 2].map(|i| self.probes[0].force.eq33(i, step.st, step.q, &sys.lam, axial))
        });
        if let (Some(fa0), Some(s)) = (fa0, self.sensors.as_mut()) {
            s.reader
                .read(step.st, (sys.nm, sys.nb), [step.q, step.v, step.qdd], fa0, &mut s.base);
        }
        let apq = self.ga.a_per_qdd();
        sys.step_residual(bp, qhat, (step.qdd, &sys.lam), &mut self.primal0, &mut self.rows0);
        // the sleeve rows' derivatives in the material points, shared by the directions and
        // their probes (the first probe is the workspace)
        self.probes[0].sys.linearise_sleeves(sys, qhat);
        // the predictor is linear in (q, v, a, q''): its rows (a_part, qhat, vhat), read off
        // once per step; at the start the predictors are the state itself
        let unit = |x: [f64; 4]| self.ga.predict(h, x[0], x[1], x[2], x[3]);
        let (ca, cq, cv) = if h > 0.0 {
            let c = [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]
            .map(unit);
            (c.map(|x| x.0), c.map(|x| x.1), c.map(|x| x.2))
        } else {
            ([0.0; 4], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0])
        };
        for (k, dir) in self.dirs.iter_mut().enumerate() {
            let eps = self.eps[k];
            let inv_eps = 1.0 / eps;
            let probe = &mut self.probes[self.probe_of[k]];
            // the tangent predictor (Eq. T-4), then the moved inputs: each a combination of the
            // slices (q, v, a, q'') of one length, in the processor's lanes
            let x = [&dir.dq[..], &dir.dv[..], &dir.dacc[..], &dir.dqdd[..]];
            combine(&mut self.da, ca, x);
            combine(&mut self.nq, cq, x);
            combine(&mut self.nv, cv, x);
            dir.dq.copy_from_slice(&self.nq);
            dir.dv.copy_from_slice(&self.nv);
            for ((m, b), d) in self.qhat.iter_mut().zip(qhat).zip(&self.nq) {
                *m = b + eps * d;
            }
            for ((m, b), d) in self.vhat.iter_mut().zip(vhat).zip(&self.nv) {
                *m = b + eps * d;
            }
            for ((l, p), d) in self.lagged.iter_mut().zip(&self.qdd_prev).zip(&dir.dqdd) {
                *l = p + eps * d;
            }
            // the moved step's equations at the base solution (Eqs. T-2, T-3)
            let st = self.moved[k].state(step.st.t)?;
            probe.sys.set_axial_acceleration(&self.lagged);
            let near = sys.sleeves.kept().expect("the run keeps its sleeve values");
            probe.sys.prepare_rows(&st, (bp, gp), &self.qhat, Some(near))?;
            probe.sys.forcing(&st, &self.qhat, &self.vhat);
            probe
                .sys
                .step_residual(bp, &self.qhat, (step.qdd, &sys.lam), &mut self.primal, &mut self.rows);
            // less the step's own residual: the probe's minus the step's, negated for the solve
            for (r, r0) in self.primal.iter_mut().zip(&self.primal0) {
                *r = r0 - *r;
            }
            for (r, r0) in self.rows.iter_mut().zip(&self.rows0) {
                *r -= r0;
            }
            sys.solve_correction(bp, (&mut self.primal, &self.rows), &mut self.corr_l, &mut self.corr_q);
            // the update (linear): q = qhat + bp q'', v = vhat + gp q'', a = a_part + apq q''
            for (d, c) in dir.dqdd.iter_mut().zip(&self.corr_q) {
                *d = c * inv_eps;
            }
            if h > 0.0 {
                for (q, d) in dir.dq.iter_mut().zip(&dir.dqdd) {
                    *q += bp * d;
                }
                for (v, d) in dir.dv.iter_mut().zip(&dir.dqdd) {
                    *v += gp * d;
                }
                for ((a, p), d) in dir.dacc.iter_mut().zip(&self.da).zip(&dir.dqdd) {
                    *a = p + apq * d;
                }
            } else {
                dir.dacc.copy_from_slice(&dir.dqdd);
            }
            // the outputs' tangents on an output row: Eq. 33 and the sensors' readings at the
            // moved state less the step's own
            if let (Some(row), Some(fa0)) = (step.output, fa0) {
                for ((m, q), d) in self.q_moved.iter_mut().zip(step.q).zip(&dir.dq) {
                    *m = q + eps * d;
                }
                for ((m, l), d) in self.lam_moved.iter_mut().zip(&sys.lam).zip(&self.corr_l) {
                    *m = l + d;
                }
                let axial = probe.sys.sleeves.axial();
                let fa = [0, 1, 2].map(|i| probe.force.eq33(i, &st, &self.q_moved, &self.lam_moved, axial));
                for (i, (f, f0)) in fa.iter().zip(fa0).enumerate() {
                    self.fa[k][i][row] = (f - f0) * inv_eps;
                }
                if let (Some(s), Some(tables)) = (self.sensors.as_mut(), self.d_sensors.as_mut()) {
                    for ((m, v), d) in s.v_moved.iter_mut().zip(step.v).zip(&dir.dv) {
                        *m = v + eps * d;
                    }
                    for ((m, a), d) in s.qdd_moved.iter_mut().zip(step.qdd).zip(&dir.dqdd) {
                        *m = a + eps * d;
                    }
                    let q3 = [&self.q_moved[..], &s.v_moved[..], &s.qdd_moved[..]];
                    s.reader.read(&st, (sys.nm, sys.nb), q3, fa, &mut s.row);
                    for (r, b) in s.row.iter_mut().zip(&s.base) {
                        *r = (*r - b) * inv_eps;
                    }
                    tables[k].push_row(step.st.t, &s.row);
                }
            }
        }
        self.qdd_prev.copy_from_slice(step.qdd);
        if let Some(row) = step.output {
            self.record(sys, row);
        }
        Ok(())
    }

    /// The tangents of w_iG and w_i(L) at output row `row` (the recorder's row of the step).
    fn record(&mut self, sys: &System, row: usize) {
        let (nm, nb) = (sys.nm, sys.nb);
        for (k, dir) in self.dirs.iter().enumerate() {
            for i in 0..3 {
                let b = sys.beam(i);
                let a = &dir.dq[i * nb..i * nb + nm];
                self.w_g[k][i][row] = dot(&b.phi0, a);
                self.w_tip[k][i][row] = dot(&b.phil, a);
            }
        }
    }
}

/// `out = w[0] x[0] + w[1] x[1] + w[2] x[2] + w[3] x[3]`, element by element (slices of one
/// length).
fn combine(out: &mut [f64], w: [f64; 4], x: [&[f64]; 4]) {
    let n = out.len();
    let [a, b, c, d] = x.map(|v| &v[..n]);
    for j in 0..n {
        out[j] = w[0] * a[j] + w[1] * b[j] + w[2] * c[j] + w[3] * d[j];
    }
}

impl StepObserver for &mut Tangent<'_> {
    fn step(&mut self, sys: &mut System, step: &Step) {
        if self.failed.is_some() {
            return;
        }
        if let Err(e) = self.advance(sys, step) {
            self.failed = Some(e);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::catalogue::paper_case;
    use flexstar_model::{AmmModel, Experiment, ModeFamily, Trajectory};

    /// Case 3 over 0.2 s, the accurate model's equations at a fixed N, with the coefficient of
    /// t^2 in s1 (1 m/s^2 on the paper's case) and of t^2 in s3 (0.5) moved by `d1` and `d3`.
    fn case3(d1: f64, d3: f64) -> Experiment {
        let mut e = paper_case(3);
        e.time.t_end = 0.2;
        e.trajectory = Trajectory::Polynomial {
            s1: vec![0.0, 0.0, 1.0 + d1],
            s2: vec![0.0],
            s3: vec![0.0, 0.0, 0.5 + d3],
        };
        e
    }

    fn settings(model: AmmModel) -> AmmSettings {
        AmmSettings {
            family: ModeFamily::Enriched,
            model,
            modes: Some(24),
            tol: None,
            dt: Some(5e-4),
            ..AmmSettings::accurate()
        }
    }

    /// The largest difference between the tangent of `w` and the central difference of whole
    /// runs at `+-delta`, over the largest central difference.
    fn worst(
        tangent: &[Vec<f64>; 3],
        plus: &Response,
        minus: &Response,
        delta: f64,
        w: fn(&Response) -> &[Vec<f64>; 3],
    ) -> f64 {
        let (mut err, mut scale) = (0.0f64, 0.0f64);
        for (i, beam) in tangent.iter().enumerate() {
            for (k, d) in beam.iter().enumerate() {
                let c = (w(plus)[i][k] - w(minus)[i][k]) / (2.0 * delta);
                err = err.max((d - c).abs());
                scale = scale.max(c.abs());
            }
        }
        err / scale
    }

    /// Asserts each direction's tangents of `w_iG`, `w_i(L)` and `Fa_i` within `tol` (relative, [`worst`])
    /// of the central differences of whole runs, `run(k, d)` being the run with direction k
    /// moved by `d`, at `+-delta`.
    fn assert_matches_differences(
        sens: &Sensitivities,
        run: impl Fn(usize, f64) -> Response,
        delta: f64,
        (tol, tol_fa): (f64, f64),
        label: &str,
    ) {
        for k in 0..sens.w_g.len() {
            let (plus, minus) = (run(k, delta), run(k, -delta));
            let eg = worst(&sens.w_g[k], &plus, &minus, delta, |r| &r.w_g);
            let et = worst(&sens.w_tip[k], &plus, &minus, delta, |r| &r.w_tip);
            let ef = worst(&sens.fa[k], &plus, &minus, delta, |r| &r.fa);
            println!("{label} direction {k}: w_G {eg:.2e}, tips {et:.2e}, Fa {ef:.2e}");
            assert!(
                eg < tol && et < tol && ef < tol_fa,
                "{label} direction {k}: w_G {eg:.2e}, tips {et:.2e}, Fa {ef:.2e}"
            );
        }
    }

    /// The plain run of `exp` at `settings`.
    fn plain(exp: &Experiment, settings: &AmmSettings) -> Response {
        let p = exp.problem().unwrap();
        crate::solve(&p, settings, flexstar_drive::SolveRequest::motion())
            .unwrap()
            .response
    }

    /// A plan's kind of motion (`docs/motions.md` 1.3, 4.2): the clamped quintic spline from the
    /// centre towards the edge through two interior points, over 0.5 s and 0.15 s at rest after
    /// it, on the paper's robot with Rayleigh damping; the interior points' `Gx` and `theta`
    /// moved by `dx` [m] and `dth` [rad].
    fn via(dx: f64, dth: f64) -> Experiment {
        via_on("", dx, dth)
    }

    /// [`via`] on the robot of the TOML section `robot` (empty: the paper's).
    fn via_on(robot: &str, dx: f64, dth: f64) -> Experiment {
        let text = format!(
            "name = \"via\"\n{robot}[time]\nt_end = 0.65\ndt_out = 0.001\n[damping]\nalpha = 0.5\nbeta = 2e-5\n\
             [trajectory]\nkind = \"via\"\nrest = false\npoints = [\n\
             {{ t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }},\n\
             {{ t = 0.17, Gx = {}, Gy = -0.02, theta = {} }},\n\
             {{ t = 0.33, Gx = 0.12, Gy = -0.07, theta = 0.0 }},\n\
             {{ t = 0.5, Gx = 0.2, Gy = -0.11, theta = 0.0 }},\n]\n",
            0.05 + dx,
            0.02 + dth
        );
        Experiment::from_toml_str(&text, std::path::Path::new("via.toml")).unwrap()
    }

    /// The tangent along a via point's coordinates against central differences of whole runs:
    /// the planner's variables (`docs/motions.md` 4.2), with damping in the step matrix. `eps`
    /// = 1e-7 m, half a millionth of the move (the second-order terms, 8.6e-6 of the derivative
    /// at `eps` = 1e-6 m and 8.6e-5 at 1e-5 m, grow like `eps`; round-off takes over below,
    /// 4.2e-6 at 1e-8 m); the differences at +-1e-5 m (theirs fall like `delta^2`: 2.0e-4 of
    /// the derivative at +-1e-3 m).
    #[test]
    fn the_tangent_along_a_via_point_matches_central_differences() {
        let s = settings(AmmModel::Full);
        let base = via(0.0, 0.0).problem().unwrap();
        let eps = 1e-7;
        let moved = [via(eps, 0.0).problem().unwrap(), via(0.0, eps).problem().unwrap()];
        let sens = solve_with_sensitivities(&base, &s, &moved, &[eps; 2]).unwrap();
        let moved = |k: usize, d: f64| if k == 0 { via(d, 0.0) } else { via(0.0, d) };
        assert_matches_differences(&sens, |k, d| plain(&moved(k, d), &s), 1e-5, (2e-6, 1.5e-3), "via");
    }

    /// A robot as built (`docs/as-built.md`): unequal beams and weld angles, each beam with
    /// its own mode set and arrowhead; the tangent along the plan-kind motion's via point
    /// against central differences, as above.
    #[test]
    fn the_tangent_holds_on_a_robot_as_built() {
        let robot = "[robot]\nL = [0.5, 0.5, 0.47]\nrho = [0.234, 0.25, 0.234]\nweld_deg = [0.0, 121.0, 238.5]\n";
        let s = settings(AmmModel::Full);
        let base = via_on(robot, 0.0, 0.0).problem().unwrap();
        let eps = 1e-7;
        let sens = solve_with_sensitivities(&base, &s, &[via_on(robot, eps, 0.0).problem().unwrap()], &[eps]).unwrap();
        assert_matches_differences(
            &sens,
            |_, d| plain(&via_on(robot, d, 0.0), &s),
            1e-5,
            (2e-6, 1.5e-3),
            "as built",
        );
    }

    /// A payload off G and a load at G (`docs/amm.md` 11.1, 11.3): the payload's step matrix
    /// `P^T S_p P` in the probe's residual and its Woodbury terms in the step's solve, the load
    /// in the forcing; the tangent along the plan-kind motion's via point against central
    /// differences at +-1e-6 m: near t = 0.45 s the forces of whole runs change slope within
    /// +-1e-5 m (their central differences there move by 0.7 % between +-1e-4 and +-1e-6, the
    /// tangent's do not); at +-1e-6 the forces agree to 7.4e-6 and 3.4e-5 of the largest
    /// derivative.
    #[test]
    fn the_tangent_holds_with_a_payload_and_a_load() {
        let attached = "[payload]\nmass = 0.3\nJ = 2e-4\noffset = [0.01, -0.005]\n\
                        [load]\nFx = [0.5, -2.0]\nMz = [0.0, 0.1]\n";
        let s = settings(AmmModel::Full);
        let base = via_on(attached, 0.0, 0.0).problem().unwrap();
        let eps = 1e-7;
        let moved = [
            via_on(attached, eps, 0.0).problem().unwrap(),
            via_on(attached, 0.0, eps).problem().unwrap(),
        ];
        let sens = solve_with_sensitivities(&base, &s, &moved, &[eps; 2]).unwrap();
        let moved = |k: usize, d: f64| {
            if k == 0 {
                via_on(attached, d, 0.0)
            } else {
                via_on(attached, 0.0, d)
            }
        };
        assert_matches_differences(
            &sens,
            |k, d| plain(&moved(k, d), &s),
            1e-6,
            (2e-6, 1.5e-3),
            "payload and load",
        );
    }

    /// The plan-kind motion on a robot with a payload, Rayleigh damping and four sensors (an
    /// accelerometer at G, one on beam 2, a strain gauge near beam 3's root, a force cell), its
    /// modulus E [Pa], payload mass [kg] and damping `beta` [s] moved by `d`: the fit's kind of
    /// parameters (`docs/measured.md` 4.5).
    fn physical(d: [f64; 3]) -> Experiment {
        let text = format!(
            "[robot]\nE = {}\n[payload]\nmass = {}\nJ = 2e-4\noffset = [0.01, -0.005]\n\
             [[sensors]]\nname = \"accG\"\nkind = \"accelerometer\"\nat = \"G\"\n\
             [[sensors]]\nname = \"accB\"\nkind = \"accelerometer\"\nbeam = 2\nx = 0.45\n\
             [[sensors]]\nname = \"root\"\nkind = \"strain\"\nbeam = 3\nx = 0.05\nc = 0.001\n\
             [[sensors]]\nname = \"cell1\"\nkind = \"force\"\nslider = 1\n",
            200e9 + d[0],
            0.3 + d[1]
        );
        let mut e = via_on(&text, 0.0, 0.0);
        e.damping.beta = Some(2e-5 + d[2]);
        e
    }

    /// The largest difference between a sensor table of derivatives and the central
    /// differences of two runs' readings at `+-delta`, over the largest central difference, per
    /// column: the worst column.
    fn worst_sensor(d: &SensorTable, plus: &Response, minus: &Response, delta: f64) -> f64 {
        let (sp, sm) = (plus.sensors.as_ref().unwrap(), minus.sensors.as_ref().unwrap());
        let mut worst = 0.0f64;
        for (c, col) in d.columns.iter().enumerate() {
            let (mut err, mut big) = (0.0f64, 0.0f64);
            for (j, v) in col.values.iter().enumerate() {
                let central = (sp.columns[c].values[j] - sm.columns[c].values[j]) / (2.0 * delta);
                err = err.max((v - central).abs());
                big = big.max(central.abs());
            }
            worst = worst.max(err / big);
        }
        worst
    }

    /// The tangent along physical parameters (each direction its own probe, built at the moved
    /// parameters; `docs/amm.md` 2.2, "Physical parameters") against central differences of
    /// whole runs at +-1e-4 of each parameter, the sensors' readings included: the largest
    /// difference 6.5e-5 to 1.6e-4 of the largest derivative (against differences at +-1e-3,
    /// whose second-order terms are the mean's own, 1.9e-6 to 1.7e-5; at +-1e-5 the damping's
    /// differences are at their round-off, 2.6e-3).
    ///
    /// One-sided, the error of a direction is its second-order terms, which grow like `eps`,
    /// plus the round-off of the residual's difference, which grows like `1 / eps` and is the
    /// larger the less the parameter moves the readings (measured, largest relative error of
    /// the outputs): E 8.8e-4 / 8.8e-5 / 8.8e-6 at `eps` = 1e-4 / 1e-5 / 1e-6 of E (second
    /// order); the damping's `beta` 3.0e-2 / 2.8e-3 / 4.6e-4 / 1.5e-4 at 1e-6 / 1e-5 / 1e-4 /
    /// 1e-3 (round-off) and 4.9e-4 at 1e-2. The mean of the directions at `+eps` and `-eps`
    /// cancels the second-order terms, so that one `eps` (1e-3 of each parameter) serves all:
    /// how the fit takes its columns (`docs/measured.md` 4.5).
    #[test]
    fn the_tangent_along_physical_parameters_matches_central_differences() {
        let s = settings(AmmModel::Full);
        let scale = [200e9, 0.3, 2e-5];
        let unit = |k: usize, d: f64| std::array::from_fn::<f64, 3, _>(|j| if j == k { d } else { 0.0 });
        let base = physical([0.0; 3]).problem().unwrap();
        let eps: Vec<f64> = scale.iter().flat_map(|x| [1e-3 * x, -1e-3 * x]).collect();
        let moved: Vec<_> = (0..6)
            .map(|j| physical(unit(j / 2, eps[j])).problem().unwrap())
            .collect();
        let sens = solve_with_sensitivities(&base, &s, &moved, &eps).unwrap();
        let alone = plain(&physical([0.0; 3]), &s);
        assert_eq!(
            alone.w_g, sens.response.w_g,
            "the run itself is the plain run's, bit for bit"
        );
        let d_sensors = sens.sensors.as_ref().expect("sensor tangents");
        let mean = |a: &[Vec<f64>; 3], b: &[Vec<f64>; 3]| -> [Vec<f64>; 3] {
            std::array::from_fn(|i| a[i].iter().zip(&b[i]).map(|(x, y)| 0.5 * (x + y)).collect())
        };
        for (k, sc) in scale.iter().enumerate() {
            let (p, m) = (2 * k, 2 * k + 1);
            let delta = 1e-4 * sc;
            let (plus, minus) = (
                plain(&physical(unit(k, delta)), &s),
                plain(&physical(unit(k, -delta)), &s),
            );
            let eg = worst(&mean(&sens.w_g[p], &sens.w_g[m]), &plus, &minus, delta, |r| &r.w_g);
            let et = worst(&mean(&sens.w_tip[p], &sens.w_tip[m]), &plus, &minus, delta, |r| {
                &r.w_tip
            });
            let ef = worst(&mean(&sens.fa[p], &sens.fa[m]), &plus, &minus, delta, |r| &r.fa);
            let mut both = d_sensors[p].clone();
            for (c, col) in both.columns.iter_mut().enumerate() {
                for (v, w) in col.values.iter_mut().zip(&d_sensors[m].columns[c].values) {
                    *v = 0.5 * (*v + w);
                }
            }
            let es = worst_sensor(&both, &plus, &minus, delta);
            let one_sided = worst_sensor(&d_sensors[p], &plus, &minus, delta);
            println!(
                "parameter {k}: w_G {eg:.2e}, tips {et:.2e}, Fa {ef:.2e}, sensors {es:.2e} (one-sided {one_sided:.2e})"
            );
            assert!(
                eg < 1e-4 && et < 1e-4 && ef < 2e-4 && es < 2e-4,
                "parameter {k}: w_G {eg:.2e}, tips {et:.2e}, Fa {ef:.2e}, sensors {es:.2e}"
            );
        }
    }

    /// What the tangent does not cover is refused before any work, naming the key.
    #[test]
    fn unsupported_runs_are_refused_before_any_work() {
        let base = case3(0.0, 0.0);
        let moved = [case3(1e-6, 0.0).problem().unwrap()];
        let auto = AmmSettings::accurate();
        let e = solve_with_sensitivities(&base.problem().unwrap(), &auto, &moved, &[1e-6]).unwrap_err();
        assert!(e.to_string().contains("amm.modes"), "{e}");
        let mut heavy = base.clone();
        heavy.gravity.g = [0.0, -9.81];
        let e = solve_with_sensitivities(&heavy.problem().unwrap(), &settings(AmmModel::Full), &moved, &[1e-6])
            .unwrap_err();
        assert!(e.to_string().contains("gravity"), "{e}");
        let mut longer = case3(1e-6, 0.0);
        longer.robot.l *= 1.01;
        let e = solve_with_sensitivities(
            &base.problem().unwrap(),
            &settings(AmmModel::Full),
            &[longer.problem().unwrap()],
            &[1e-6],
        )
        .unwrap_err();
        assert!(e.to_string().contains("same mode basis"), "{e}");
    }

    /// Eqs. T-1 to T-4 against central differences of whole runs, both models: the derivatives
    /// of w_iG and w_i(L) along two coefficients of the motion agree to the digits the
    /// differences allow (their truncation, `delta^2` times the third derivative, and their
    /// round-off, about `1e-16 / delta` of the outputs).
    #[test]
    fn the_tangent_matches_central_differences_of_whole_runs() {
        for model in [AmmModel::Paper, AmmModel::Full] {
            let s = settings(model);
            let base = case3(0.0, 0.0).problem().unwrap();
            let eps = 1e-6;
            let moved = [case3(eps, 0.0).problem().unwrap(), case3(0.0, eps).problem().unwrap()];
            let sens = solve_with_sensitivities(&base, &s, &moved, &[eps; 2]).unwrap();
            let alone = plain(&case3(0.0, 0.0), &s);
            assert_eq!(
                alone.w_g, sens.response.w_g,
                "the run itself is the plain run's, bit for bit"
            );
            let moved = |k: usize, d: f64| if k == 0 { case3(d, 0.0) } else { case3(0.0, d) };
            let label = format!("{model:?}");
            assert_matches_differences(&sens, |k, d| plain(&moved(k, d), &s), 1e-4, (1e-6, 2e-4), &label);
        }
    }
}
