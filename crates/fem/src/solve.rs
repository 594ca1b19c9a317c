//! The public entry point: run the FEM on an experiment and post-process its absolute results
//! into the shared [`Response`] (projections of `docs/conventions.md`).

use flexstar_kinematics::{check_trajectory, RigidState};
use flexstar_model::{BeamShape, Experiment, FemSettings, Response, RunInfo, StarShape};

use crate::integrator::{integrate, RunSettings, Stats};
use crate::star::InitialState;
use crate::FemError;

/// Default integration step [s], from the convergence study in `docs/fem.md`.
pub const DEFAULT_DT: f64 = 5e-4;
/// Default spectral radius at infinity of the generalized-alpha scheme (docs/fem.md).
pub const DEFAULT_RHO_INF: f64 = 0.7;

/// Run the finite-element reference on `exp` with `settings` (which override `exp.fem`).
///
/// Returns the response labelled `fem` at `exp.time.output_times()`:
/// - `w_iG = (G_fem - G_rigid) . e_wi` and the tip value `w_i(L) = (tip_fem - (G_rigid + L e_xi)) . e_wi`
///   [m], projected on the rigid frames of Eqs. 11-12 (post-processing only);
/// - `Fa_i` [N], Eq. 33, from the pin reactions: `Fa_i = (mpp + mpa) s_i'' + F_i . u_i` with `F_i`
///   the force the sleeve exerts on the beam (sum over centre and edges) and `u_i` the slider
///   direction;
/// - extra columns: `xp1..3` (material coordinate of each sleeve centre on its beam [m]),
///   `thp1..3` (sleeve rotation relative to the rigid beam direction [rad]), `Fn1..3` (force of
///   sleeve i on its beam along e_wi [N], the paper's `Fp + FL + FR`), `dGx, dGy` (G_fem - G_rigid
///   in the fixed frame [m]), `Ek_star, Ek_sleeves, Ek_sliders, U` (kinetic energies of beams,
///   sleeve rotations, sliders and strain energy [J]), `W` (work of the drivers since t = 0 [J]),
///   `slopeG` (elastic slope of the beams at G: rotation of the weld node minus the rigid
///   rotation theta(t) - theta(0) [rad]; the junction measure of Table I);
/// - `shapes`: the deformed star at `settings.snapshots` and at t_end.
///
/// `progress` receives the fraction of the time span done, in [0, 1].
pub fn solve(
    exp: &Experiment,
    settings: &FemSettings,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<Response, FemError> {
    solve_with_stats(exp, settings, progress).map(|(r, _)| r)
}

/// [`solve`], also returning the work counters (steps, Newton iterations, factorisations).
pub fn solve_with_stats(
    exp: &Experiment,
    settings: &FemSettings,
    progress: Option<&(dyn Fn(f64) + Sync)>,
) -> Result<(Response, Stats), FemError> {
    let started = std::time::Instant::now();
    let params = &exp.robot;
    params.validate().map_err(|e| FemError::Input(e.to_string()))?;
    exp.time.validate().map_err(|e| FemError::Input(e.to_string()))?;
    exp.trajectory
        .validate(params)
        .map_err(|e| FemError::Input(e.to_string()))?;
    if settings.elements < 3 || !settings.elements.is_multiple_of(3) {
        return Err(FemError::Input(format!(
            "fem.elements must be a positive multiple of 3 (three equal beams), got {}",
            settings.elements
        )));
    }
    let dt = settings.dt.unwrap_or(DEFAULT_DT.min(exp.time.dt_out));
    if !(dt.is_finite() && dt > 0.0) {
        return Err(FemError::Input(format!("fem.dt must be positive, got {dt}")));
    }
    let rho_inf = settings.rho_inf.unwrap_or(DEFAULT_RHO_INF);
    if !(0.0..=1.0).contains(&rho_inf) {
        return Err(FemError::Input(format!(
            "fem.rho_inf must lie in [0, 1], got {rho_inf}"
        )));
    }
    let t_end = exp.time.t_end;
    if let Some(bad) = settings
        .snapshots
        .iter()
        .find(|t| !(t.is_finite() && **t >= 0.0 && **t <= t_end))
    {
        return Err(FemError::Input(format!(
            "fem.snapshots must lie in [0, t_end = {t_end}], got {bad}"
        )));
    }
    // the same feasibility scan as the AMM and the kinematics, before any work: a pre-flight check
    // of the requested motion only (the FEM's equations never use the rigid kinematics)
    check_trajectory(params, &exp.trajectory, t_end, exp.time.dt_out.min(1e-3))
        .map_err(|e| FemError::Input(e.to_string()))?;
    let rigid = |t: f64| {
        RigidState::at(params, &exp.trajectory, t).map_err(|e| FemError::PostProcessing {
            t,
            reason: e.to_string(),
        })
    };

    // initial data: the undeformed star in the rigid configuration at s(0), moving rigidly
    let r0 = rigid(0.0)?;
    let init = InitialState {
        g: [r0.g[0].v, r0.g[1].v],
        g_dot: [r0.g[0].d1, r0.g[1].d1],
        theta: r0.theta.v,
        theta_dot: r0.theta.d1,
        xp: r0.xp.map(|x| x.v),
        xp_dot: r0.xp.map(|x| x.d1),
    };
    let t_out = exp.time.output_times();
    let mut snaps = settings.snapshots.clone();
    snaps.push(t_end);
    snaps.sort_by(|a, b| a.total_cmp(b));
    snaps.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let run = RunSettings {
        ne: settings.elements / 3,
        dt,
        rho_inf,
    };
    let hist = integrate(params, &exp.trajectory, &t_out, &snaps, &init, &run, progress)?;

    // post-processing with the rigid kinematics
    let n = hist.samples.len();
    let mut resp = Response::with_capacity("fem", n);
    let names = [
        "xp1",
        "xp2",
        "xp3",
        "thp1",
        "thp2",
        "thp3",
        "Fn1",
        "Fn2",
        "Fn3",
        "dGx",
        "dGy",
        "Ek_star",
        "Ek_sleeves",
        "Ek_sliders",
        "U",
        "W",
        "slopeG",
    ];
    let mut extra: Vec<Vec<f64>> = vec![Vec::with_capacity(n); names.len()];
    for s in &hist.samples {
        let r = rigid(s.t)?;
        let g = [r.g[0].v, r.g[1].v];
        let dg = [s.g[0] - g[0], s.g[1] - g[1]];
        let mut w_g = [0.0; 3];
        let mut w_tip = [0.0; 3];
        for i in 0..3 {
            let (ex, ew) = (r.e_x(i), r.e_w(i));
            w_g[i] = dot(dg, ew);
            let rel = [
                s.tip[i][0] - g[0] - params.l * ex[0],
                s.tip[i][1] - g[1] - params.l * ex[1],
            ];
            w_tip[i] = dot(rel, ew);
            extra[i].push(s.xi_c[i]);
            extra[3 + i].push(wrap(s.sleeve_angle[i] - ex[1].atan2(ex[0])));
            extra[6 + i].push(-dot(s.pin_force[i], ew));
        }
        resp.push(s.t, w_g, w_tip, s.fa);
        let slope_g = wrap(s.phi_g - (r.theta.v - r0.theta.v));
        for (k, v) in [
            dg[0],
            dg[1],
            s.ke_star,
            s.ke_sleeves,
            s.ke_sliders,
            s.strain,
            s.work,
            slope_g,
        ]
        .into_iter()
        .enumerate()
        {
            extra[9 + k].push(v);
        }
    }
    resp.set_extra(&names, extra);
    for snap in &hist.snapshots {
        let r = rigid(snap.t)?;
        let g = [r.g[0].v, r.g[1].v];
        let beams = [0, 1, 2].map(|i| {
            let (ex, ew) = (r.e_x(i), r.e_w(i));
            let pos = snap.beams[i].clone();
            let w = hist
                .node_x
                .iter()
                .zip(&pos)
                .map(|(x, p)| dot([p[0] - g[0] - x * ex[0], p[1] - g[1] - x * ex[1]], ew))
                .collect();
            BeamShape {
                x: hist.node_x.clone(),
                w,
                pos,
            }
        });
        resp.shapes.push(StarShape { t: snap.t, beams });
    }
    if let Some(cb) = progress {
        cb(1.0);
    }
    resp.info = RunInfo {
        solver: "fem".into(),
        elements: Some(settings.elements),
        dt,
        wall_s: started.elapsed().as_secs_f64(),
        ..RunInfo::default()
    };
    Ok((resp, hist.stats))
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn wrap(a: f64) -> f64 {
    use std::f64::consts::PI;
    (a + PI).rem_euclid(2.0 * PI) - PI
}
