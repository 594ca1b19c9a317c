//! The outputs of an AMM run at its output times and snapshots (shared by the inverse run,
//! [`crate::solve`] of a prescribed motion, and the direct run, [`crate::solve`] under a law).

use flexstar_kinematics::RigidState;
use flexstar_model::animation::ShapeTimes;
use flexstar_model::{AmmModel, AmmSettings, BeamShape, Frame, FramePose, Response, StarShape};

use crate::sensors::SensorRecorder;
use crate::sleeve::{self, SleeveRow};
use crate::solver::{Stop, EXTRA_COLUMNS, SHAPE_POINTS};
use crate::star::{Star, Weld};
use crate::system::{Row, System};

/// Output buffers, sized once.
pub(crate) struct Recorder {
    resp: Response,
    extra: Vec<Vec<f64>>,
    /// The snapshot points of each beam, `x = 0, L_i / 100, ..., L_i` [m].
    xs: [Vec<f64>; 3],
    /// The modes at the snapshot points, per beam (one list for equal beams).
    shape_phi: Vec<Vec<Vec<f64>>>,
    shapes: Vec<StarShape>,
    /// Rigid pose at each shape time (what an animation frame is drawn about).
    poses: Vec<FramePose>,
    /// The shape times: which are snapshots, which animation frames.
    times: ShapeTimes,
    /// `phi(0)` and `phi(L)` of each beam's modes (one for equal beams).
    phi0: Vec<Vec<f64>>,
    phil: Vec<Vec<f64>>,
    nm: usize,
    nb: usize,
    /// The multipliers' columns and the actuator forces (Eq. 33).
    pub(crate) force: SliderForce,
    /// The sensors' readings (`docs/sensors.md`), `None` without sensors.
    sensors: Option<SensorRecorder>,
}

/// What Eq. 33 needs beyond the state: each named multiplier column's row, the sliders' masses,
/// gravity along the rails and the weld (shared by the recorder and the tangent's forces).
#[derive(Debug, Clone)]
pub(crate) struct SliderForce {
    /// Multiplier index of each named multiplier column (`None`: row dropped for the family).
    col_rows: [Option<usize>; 19],
    nm: usize,
    nb: usize,
    full: bool,
    /// Each sleeve's and slider's mass `(mpp + mpa)_i` [kg] (Eq. 33).
    mpp_mpa: [f64; 3],
    /// `g . u_i` [m/s^2]: gravity along each slider's rail (Eq. G2).
    gravity_along: [f64; 3],
    /// The rails and the weld (Eq. J7).
    weld: Weld,
}

impl SliderForce {
    /// The forces of `sys`'s rows in `model`, on the robot of `problem`.
    pub(crate) fn new(sys: &System, model: AmmModel, problem: &Star) -> Self {
        let lam_index = |r: Row| sys.rows.iter().position(|x| *x == r);
        // the junction's multipliers, then the sleeves' in the columns' order Fp1..3, FLp1..3,
        // FRp1..3, Mp1..3 of EXTRA_COLUMNS
        let junction = [
            Some(Row::Fix(0)),
            Some(Row::Fix(1)),
            Some(Row::Fix(2)),
            Some(Row::M1G),
            None, // M2G = -M1G - M3G (Eq. 25-1)
            Some(Row::M3G),
            Some(Row::Fw),
        ];
        let sleeves = [SleeveRow::Fp, SleeveRow::FL, SleeveRow::FR, SleeveRow::Mp]
            .into_iter()
            .flat_map(|r| (0..3).map(move |i| Some(Row::Sleeve(i, r))));
        let mut col_rows = [None; 19];
        for (c, row) in col_rows.iter_mut().zip(junction.into_iter().chain(sleeves)) {
            *c = row.and_then(lam_index);
        }
        SliderForce {
            col_rows,
            nm: sys.nm,
            nb: sys.nb,
            full: model == AmmModel::Full,
            mpp_mpa: problem.beams.map(|b| b.mpp_mpa),
            gravity_along: problem.weld.along_rails(sys.gravity()),
            weld: problem.weld,
        }
    }

    /// `(mpp + mpa)_i` [kg] of slider i (Eq. 33).
    pub(crate) fn mass(&self, i: usize) -> f64 {
        self.mpp_mpa[i]
    }

    /// `g . u_i` [m/s^2] of slider i's rail (Eq. G2).
    pub(crate) fn gravity_along(&self, i: usize) -> f64 {
        self.gravity_along[i]
    }

    /// The multiplier of named column `k` (0 when the row is dropped).
    #[inline]
    pub(crate) fn lam_of(&self, lam: &[f64], k: usize) -> f64 {
        self.col_rows[k].map_or(0.0, |r| lam[r])
    }

    /// Eq. 33 without the slider's inertia: the component along `+u_i` of the force of sleeve i on
    /// beam i [N] ([`sleeve::rows::push`]), linear in the multipliers `lam`, with the sleeve
    /// rotation of `q` and the u gradients `axial` of the sleeve rows (-w', full model).
    #[inline]
    pub(crate) fn sleeve_push(&self, i: usize, st: &RigidState, q: &[f64], lam: &[f64], axial: &[[f64; 3]; 3]) -> f64 {
        let forces = [
            self.lam_of(lam, 7 + i),
            self.lam_of(lam, 10 + i),
            self.lam_of(lam, 13 + i),
        ];
        let thp = q[i * self.nb + self.nm + 1];
        sleeve::rows::push(self.full, i, st, thp, forces, axial[i], &self.weld)
    }

    /// Eq. 33 with the sleeve and slider's weight along the rail (Eq. G2): the actuator force of
    /// slider i [N] of a prescribed motion at the rigid state `st`, coordinates `q`, multipliers
    /// `lam` and the rows' u gradients `axial`.
    #[inline]
    pub(crate) fn eq33(&self, i: usize, st: &RigidState, q: &[f64], lam: &[f64], axial: &[[f64; 3]; 3]) -> f64 {
        self.mpp_mpa[i] * (st.s[i].d2 - self.gravity_along[i]) + self.sleeve_push(i, st, q, lam, axial)
    }

    /// `e_xi . u_i` [-]: beam i's axis at the rigid state `st` along its slider's rail (Eq. F12).
    pub(crate) fn along_rail(&self, i: usize, st: &RigidState) -> f64 {
        let (ex, d) = (st.e_x(i), self.weld.rails[i]);
        ex[0] * d[0] + ex[1] * d[1]
    }
}

impl Recorder {
    pub(crate) fn new(sys: &System, settings: &AmmSettings, problem: &Star, n_out: usize, times: ShapeTimes) -> Self {
        let (nm, nb) = (sys.nm, sys.nb);
        let extra: Vec<Vec<f64>> = (0..EXTRA_COLUMNS.len()).map(|_| Vec::with_capacity(n_out)).collect();
        let xs: [Vec<f64>; 3] = std::array::from_fn(|i| {
            let l = problem.beam(i).l;
            (0..SHAPE_POINTS)
                .map(|k| l * k as f64 / (SHAPE_POINTS - 1) as f64)
                .collect()
        });
        let shape_phi: Vec<Vec<Vec<f64>>> = (sys.bm.iter().zip(&xs))
            .map(|(b, xs)| {
                xs.iter()
                    .map(|&x| {
                        let mut v = vec![0.0; nm];
                        b.modes.values_at(x, &mut v, None);
                        v
                    })
                    .collect()
            })
            .collect();
        let shapes: Vec<StarShape> = times
            .all
            .iter()
            .map(|&t| StarShape {
                t,
                beams: std::array::from_fn(|i| BeamShape {
                    x: xs[i].clone(),
                    w: vec![0.0; SHAPE_POINTS],
                    pos: vec![[0.0; 2]; SHAPE_POINTS],
                }),
            })
            .collect();
        Recorder {
            resp: Response::with_capacity(String::new(), n_out),
            extra,
            xs,
            shape_phi,
            poses: vec![FramePose::default(); times.all.len()],
            times,
            shapes,
            phi0: sys.bm.iter().map(|b| b.phi0.clone()).collect(),
            phil: sys.bm.iter().map(|b| b.phil.clone()).collect(),
            nm,
            nb,
            force: SliderForce::new(sys, settings.model, problem),
            sensors: SensorRecorder::new(problem.sensors, sys, problem.gravity, n_out),
        }
    }

    /// Record the state at `stop`: a snapshot of the deformed star and/or an output row (with
    /// the sensors' readings, from q, the rates `v` and the consistent accelerations `qdd` of
    /// `rates`). `fa`: the actuator forces to write (a direct run's law); `None` computes them by
    /// Eq. 33.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &mut self,
        st: &RigidState,
        stop: &Stop,
        q: &[f64],
        [v, qdd]: [&[f64]; 2],
        lam: &[f64],
        axial: &[[f64; 3]; 3],
        fa: Option<[f64; 3]>,
    ) {
        let (nm, nb) = (self.nm, self.nb);
        let beam_val =
            |i: usize, coef: &[f64]| -> f64 { q[i * nb..i * nb + nm].iter().zip(coef).map(|(a, p)| a * p).sum() };
        if let Some(s) = stop.snapshot {
            self.poses[s] = FramePose {
                g: [st.g[0].v, st.g[1].v],
                theta: st.theta.v,
                s: st.s.map(|x| x.v),
            };
            let shape = &mut self.shapes[s];
            for i in 0..3 {
                let (ex, ew) = (st.e_x(i), st.e_w(i));
                let u = q[i * nb + nm];
                let b = &mut shape.beams[i];
                let shape_phi = crate::system::pick(&self.shape_phi, i);
                for (k, phi) in shape_phi.iter().enumerate() {
                    let w = beam_val(i, phi);
                    let x = self.xs[i][k] + u;
                    b.w[k] = w;
                    b.pos[k] = [st.g[0].v + x * ex[0] + w * ew[0], st.g[1].v + x * ex[1] + w * ew[1]];
                }
            }
        }
        if stop.output.is_some() {
            use crate::system::pick;
            let w_g = [0, 1, 2].map(|i| beam_val(i, pick::<Vec<f64>>(&self.phi0, i)));
            let w_tip = [0, 1, 2].map(|i| beam_val(i, pick::<Vec<f64>>(&self.phil, i)));
            let fa = fa.unwrap_or_else(|| [0, 1, 2].map(|i| self.force.eq33(i, st, q, lam, axial)));
            self.resp.push(st.t, w_g, w_tip, fa);
            if let Some(s) = &mut self.sensors {
                s.record(st, (nm, nb), [q, v, qdd], fa);
            }
            let dg = self.force.weld.dg(w_g, [0, 1, 2].map(|i| st.e_w(i)));
            for k in 0..self.extra.len() {
                let val = match k {
                    4 => -self.force.lam_of(lam, 3) - self.force.lam_of(lam, 5),
                    0..=18 => self.force.lam_of(lam, k),
                    19..=21 => q[(k - 19) * nb + nm + 1],
                    22..=24 => q[(k - 22) * nb + nm],
                    _ => dg[k - 25],
                };
                self.extra[k].push(val);
            }
        }
    }

    /// The response labelled `label`, with the columns [`EXTRA_COLUMNS`], the snapshots and the
    /// animation frames.
    pub(crate) fn finish(self, label: String) -> Response {
        let mut resp = self.resp;
        resp.label = label;
        resp.set_extra(&EXTRA_COLUMNS, self.extra);
        resp.frames = (self.times.frame_idx.iter())
            .map(|&k| Frame {
                shape: self.shapes[k].clone(),
                pose: self.poses[k],
            })
            .collect();
        resp.shapes = self.times.snap_idx.iter().map(|&k| self.shapes[k].clone()).collect();
        resp.sensors = self.sensors.map(SensorRecorder::finish);
        resp
    }
}
