//! The AMM's material points for the sensors (`docs/sensors.md` sections 2-4, Eqs. S1-S3, S6):
//! the acceleration, tangent and curvature of a point of beam i from the modal coordinates q,
//! their rates q' and the consistent accelerations q'' at an output time.

use flexstar_kinematics::RigidState;
use flexstar_model::sensors::{Instant, JunctionMotion, PointMotion, SensorTable, Sensors};

use crate::system::{pick, System};

/// A material point of a beam and its modes there: `phi_m`, `phi_m'`, `phi_m''` at x.
struct ModalPoint {
    beam: usize,
    x: f64,
    phi: [Vec<f64>; 3],
}

/// The sensors of a run, their points' modes (evaluated once) and the readings so far.
pub(crate) struct SensorRecorder {
    sensors: Sensors,
    points: Vec<ModalPoint>,
    gravity: [f64; 2],
    raw: SensorTable,
}

impl SensorRecorder {
    /// The recorder of `sensors` on the system `sys` (its mode sets), `None` without sensors;
    /// `gravity` [m/s^2], base frame; room for `n_out` rows.
    pub(crate) fn new(sensors: &Sensors, sys: &System, gravity: [f64; 2], n_out: usize) -> Option<Self> {
        if sensors.is_empty() {
            return None;
        }
        // G (beam 1 at x = 0) for the payload's frame, and every point on a beam
        let wanted = std::iter::once((0, 0.0)).chain(sensors.list().iter().filter_map(|s| s.beam_point()));
        let mut points: Vec<ModalPoint> = Vec::new();
        for (beam, x) in wanted {
            if points.iter().any(|p| p.beam == beam && p.x == x) {
                continue;
            }
            let modes = &pick(&sys.bm, beam).modes;
            let evals: Vec<[f64; 4]> = (0..sys.nm).map(|m| modes.eval(m, x)).collect();
            points.push(ModalPoint {
                beam,
                x,
                phi: [0, 1, 2].map(|d| evals.iter().map(|e| e[d]).collect()),
            });
        }
        Some(SensorRecorder {
            sensors: sensors.clone(),
            points,
            gravity,
            raw: SensorTable::with_columns(&sensors.units(), n_out),
        })
    }

    /// Record the readings at the rigid state `st` with the coordinates `q`, rates `v`,
    /// accelerations `qdd` (the system's layout: per beam N modes, u, the sleeve rotation) and
    /// the actuator forces `fa` [N].
    pub(crate) fn record(&mut self, st: &RigidState, (nm, nb): (usize, usize), q: [&[f64]; 3], fa: [f64; 3]) {
        let mut row = Vec::with_capacity(self.raw.columns.len());
        self.read(st, (nm, nb), q, fa, &mut row);
        self.raw.push_row(st.t, &row);
    }

    /// The readings at `st` with `q` = (q, q', q'') and the forces `fa` [N] into `row` (cleared
    /// first), in the table's column order; nothing recorded.
    pub(crate) fn read(
        &self,
        st: &RigidState,
        (nm, nb): (usize, usize),
        q: [&[f64]; 3],
        fa: [f64; 3],
        row: &mut Vec<f64>,
    ) {
        let at = AmmInstant {
            st,
            nm,
            nb,
            q,
            fa,
            points: &self.points,
        };
        row.clear();
        self.sensors.read(&at, self.gravity, row);
    }

    /// An empty table of the readings' columns (names and units), with room for `n_out` rows.
    pub(crate) fn empty_table(&self, n_out: usize) -> SensorTable {
        SensorTable::with_columns(&self.sensors.units(), n_out)
    }

    /// The number of columns a row of [`SensorRecorder::read`] has.
    pub(crate) fn width(&self) -> usize {
        self.raw.columns.len()
    }

    /// The readings at the output times.
    pub(crate) fn finish(self) -> SensorTable {
        self.raw
    }
}

/// One output time of the AMM as the sensors see it.
struct AmmInstant<'a> {
    st: &'a RigidState,
    nm: usize,
    nb: usize,
    /// q, q', q''.
    q: [&'a [f64]; 3],
    fa: [f64; 3],
    points: &'a [ModalPoint],
}

impl AmmInstant<'_> {
    /// `d^k/dx^k` of `w_i` (k = 0, 1, 2) and its first two time derivatives at the point `p`:
    /// `[[w, w_dot, w_ddot], [w', ..], [w'', ..]]`.
    fn deflection(&self, p: &ModalPoint) -> [[f64; 3]; 3] {
        let base = p.beam * self.nb;
        p.phi.each_ref().map(|phi| {
            self.q
                .map(|c| c[base..base + self.nm].iter().zip(phi).map(|(a, b)| a * b).sum::<f64>())
        })
    }

    fn point(&self, beam: usize, x: f64) -> &ModalPoint {
        self.points
            .iter()
            .find(|p| p.beam == beam && p.x == x)
            .expect("every sensor's point is evaluated when the recorder is built")
    }
}

/// `atan(s)` and its first two time derivatives from `s`, `s'`, `s''` (Eq. S3's slope angle).
fn atan_jet([s, sd, sdd]: [f64; 3]) -> [f64; 3] {
    let d = 1.0 + s * s;
    [s.atan(), sd / d, sdd / d - 2.0 * s * sd * sd / (d * d)]
}

impl Instant for AmmInstant<'_> {
    /// Eqs. S2, S3 and `kappa = w''`.
    fn beam_point(&self, beam: usize, x: f64) -> PointMotion {
        let st = self.st;
        let [w, slope, curv] = self.deflection(self.point(beam, x));
        let k = beam * self.nb + self.nm;
        let [u, ud, udd] = self.q.map(|c| c[k]);
        let (th, thd, thdd) = (st.theta.v, st.theta.d1, st.theta.d2);
        let (ex, ew) = (st.e_x(beam), st.e_w(beam));
        let r = x + u;
        let along = udd - r * thd * thd - 2.0 * w[1] * thd - w[0] * thdd;
        let normal = r * thdd + 2.0 * ud * thd + w[2] - w[0] * thd * thd;
        PointMotion {
            acc: [0, 1].map(|c| st.g[c].d2 + along * ex[c] + normal * ew[c]),
            beta: th + st.weld[beam] + slope[0].atan(),
            kappa: curv[0],
        }
    }

    /// G as beam 1's point at x = 0, `psi` its tangent's angle (Eq. S6).
    fn junction(&self) -> JunctionMotion {
        let g = self.beam_point(0, 0.0);
        let [_, slope, _] = self.deflection(self.point(0, 0.0));
        let a = atan_jet(slope);
        JunctionMotion {
            acc: g.acc,
            psi: g.beta,
            psi_d: self.st.theta.d1 + a[1],
            psi_dd: self.st.theta.d2 + a[2],
        }
    }

    fn slider(&self, i: usize) -> f64 {
        self.st.s[i].v
    }

    fn force(&self, i: usize) -> f64 {
        self.fa[i]
    }
}
