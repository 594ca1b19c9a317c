//! Output samples at the requested times and snapshots of the deformed shape.

use super::*;

/// What the solver records at one output time (fixed frame, SI).
#[derive(Debug, Clone)]
pub(crate) struct Sample {
    pub t: f64,
    /// Position of the weld node G [m].
    pub g: [f64; 2],
    /// Rotation increment of the weld node G since t = 0 [rad].
    pub phi_g: f64,
    /// Tip positions [m].
    pub tip: [[f64; 2]; 3],
    /// Absolute sleeve angles `gamma0_i + psi_i` [rad].
    pub sleeve_angle: [f64; 3],
    /// Contact coordinates (centre) xi_ic [m].
    pub xi_c: [f64; 3],
    /// Driving forces (Eq. 33) [N].
    pub fa: [f64; 3],
    /// Force the beam exerts on sleeve i, hence on its pin [N], fixed frame.
    pub pin_force: [[f64; 2]; 3],
    /// Kinetic energy of the beams, sleeves (rotation), sliders [J]; strain energy [J].
    pub ke_star: f64,
    pub ke_sleeves: f64,
    pub ke_sliders: f64,
    pub strain: f64,
    /// Work of the three drivers since t = 0 [J] (trapezoidal rule on the integration steps).
    pub work: f64,
    /// Kinetic energy of the payload [J] (0 without one).
    pub ke_payload: f64,
    /// Work of the load at G since t = 0 [J] (0 without one; trapezoidal rule on the steps).
    pub w_load: f64,
    /// Energy dissipated by the damping since t = 0 [J] (Eqs. D10, D16; 0 undamped).
    pub e_d: f64,
    /// Potential energy of the weights [J] (`Star::gravity_potential`; 0 without gravity).
    pub v_g: f64,
    /// Slider positions s_i [m] and speeds s_i' [m/s] (prescribed, or simulated).
    pub s: [f64; 3],
    pub sd: [f64; 3],
    /// With friction: the sleeves' friction and its energy.
    pub friction: Option<FrictionSample>,
}

pub(crate) use flexstar_model::FrictionSample;

/// Deformed star at one instant: node positions of each beam from G to the tip [m].
#[derive(Debug, Clone)]
pub(crate) struct Snapshot {
    pub t: f64,
    /// Slider positions s_i [m].
    pub s: [f64; 3],
    pub beams: [Vec<[f64; 2]>; 3],
}

/// Every output and snapshot time in `[0, t_end]`, sorted, duplicates removed: the step
/// boundaries.
pub(super) fn event_times(t_out: &[f64], snap_times: &[f64]) -> Vec<f64> {
    let t_end = *t_out.last().unwrap_or(&0.0);
    let mut events: Vec<f64> = t_out
        .iter()
        .chain(snap_times.iter())
        .copied()
        .filter(|t| *t >= 0.0 && *t <= t_end)
        .collect();
    events.sort_by(|a, b| a.total_cmp(b));
    events.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    events
}

/// The recorded history being built: output samples and snapshots at their times.
pub(super) struct Recorder<'a> {
    t_out: &'a [f64],
    snaps: Vec<f64>,
    out_k: usize,
    snap_k: usize,
    pub(super) samples: Vec<Sample>,
    pub(super) snapshots: Vec<Snapshot>,
    /// The sensors' readings (`docs/sensors.md`), `None` without sensors.
    pub(super) sensors: Option<crate::sensors::SensorRecorder>,
}

impl<'a> Recorder<'a> {
    /// The recorder of the output times `t_out` and the snapshots `snap_times` [s], with the
    /// readings of `sensors` (none when `None`).
    pub(super) fn new(t_out: &'a [f64], snap_times: &[f64], sensors: Option<crate::sensors::SensorRecorder>) -> Self {
        let mut snaps = snap_times.to_vec();
        snaps.sort_by(|a, b| a.total_cmp(b));
        Recorder {
            t_out,
            snaps,
            out_k: 0,
            snap_k: 0,
            samples: Vec::with_capacity(t_out.len()),
            snapshots: Vec::new(),
            sensors,
        }
    }

    /// Record the state at time `t` if it is an output or a snapshot time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn record(
        &mut self,
        star: &Star,
        st: &State,
        fa: [f64; 3],
        pin_force: [[f64; 2]; 3],
        t: f64,
        works: &Works,
    ) {
        let (q, v, pins) = (&st.q, &st.v, &st.pins);
        if self.out_k < self.t_out.len() && (self.t_out[self.out_k] - t).abs() < 1e-12 {
            let pos = |j: usize| [q[3 * j], q[3 * j + 1]];
            let (ke_star, strain) = star.beam_energies(q, v);
            self.samples.push(Sample {
                t: self.t_out[self.out_k],
                g: pos(0),
                phi_g: q[2],
                tip: [0, 1, 2].map(|i| pos(star.node(i, star.ne))),
                sleeve_angle: [0, 1, 2].map(|i| star.sleeve_angle(i, q)),
                xi_c: [0, 1, 2].map(|i| star.sleeve_centre(i, q)),
                fa,
                pin_force,
                ke_star,
                ke_sleeves: star.sleeve_energy(v),
                ke_sliders: star.slider_energy(pins),
                strain,
                work: works.work,
                ke_payload: star.payload_energy(q, v),
                w_load: works.w_load,
                e_d: works.e_d,
                v_g: star.gravity_potential(q, pins),
                s: pins.s.map(|s| s[0]),
                sd: pins.s.map(|s| s[1]),
                friction: star.friction.as_ref().map(|fr| FrictionSample {
                    ff: [0, 1, 2].map(|i| star.sleeve_friction_force(i, q, &st.lam, pins)),
                    vs: [0, 1, 2].map(|i| v[star.xi(i, 0)]),
                    stuck: fr.sleeves.map(|c| c.stuck().is_some()),
                    e_f: works.friction.map_or(0.0, |f| f.tally.dissipated()),
                }),
            });
            if let Some(s) = &mut self.sensors {
                s.record(star, self.t_out[self.out_k], [q, v, &st.qdd], pins.s.map(|s| s[0]), fa);
            }
            self.out_k += 1;
        }
        while self.snap_k < self.snaps.len() && (self.snaps[self.snap_k] - t).abs() < 1e-12 {
            let beams = [0, 1, 2].map(|i| {
                (0..=star.ne)
                    .map(|k| {
                        let j = star.node(i, k);
                        [q[3 * j], q[3 * j + 1]]
                    })
                    .collect()
            });
            self.snapshots.push(Snapshot {
                t: self.snaps[self.snap_k],
                s: pins.s.map(|s| s[0]),
                beams,
            });
            self.snap_k += 1;
        }
    }
}
