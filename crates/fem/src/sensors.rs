//! The FEM's material points for the sensors (`docs/sensors.md` section 4, Eqs. S8, S9): a point
//! of beam i at x is the point `zeta` of the element that holds it, read through the element's
//! own interpolation (`crate::element`), with the consistent accelerations of the step.

use flexstar_model::sensors::{Instant, JunctionMotion, PointMotion, SensorTable, Sensors};

use crate::element::ElementState;
use crate::star::Star;

/// The sensors of a run and their readings so far.
pub(crate) struct SensorRecorder {
    sensors: Sensors,
    gravity: [f64; 2],
    raw: SensorTable,
}

impl SensorRecorder {
    /// The recorder of `sensors` (`None` without any) under gravity `gravity` [m/s^2], base
    /// frame, with room for `n_out` rows.
    pub(crate) fn new(sensors: &Sensors, gravity: [f64; 2], n_out: usize) -> Option<Self> {
        (!sensors.is_empty()).then(|| SensorRecorder {
            sensors: sensors.clone(),
            gravity,
            raw: SensorTable::with_columns(&sensors.units(), n_out),
        })
    }

    /// Record the readings at time `t` [s]: coordinates `q`, velocities `v`, consistent
    /// accelerations `qdd` of `star`, slider positions `s` [m] and actuator forces `fa` [N].
    pub(crate) fn record(&mut self, star: &Star, t: f64, [q, v, qdd]: [&[f64]; 3], s: [f64; 3], fa: [f64; 3]) {
        let at = FemInstant { star, q, v, qdd, s, fa };
        let mut row = Vec::with_capacity(self.raw.columns.len());
        self.sensors.read(&at, self.gravity, &mut row);
        self.raw.push_row(t, &row);
    }

    /// The readings at the output times.
    pub(crate) fn finish(self) -> SensorTable {
        self.raw
    }
}

/// One output time of the FEM as the sensors see it.
struct FemInstant<'a> {
    star: &'a Star,
    q: &'a [f64],
    v: &'a [f64],
    qdd: &'a [f64],
    s: [f64; 3],
    fa: [f64; 3],
}

impl Instant for FemInstant<'_> {
    /// Eq. S8, the element's cross-section angle and Eq. S9.
    fn beam_point(&self, beam: usize, x: f64) -> PointMotion {
        let star = self.star;
        let (e, zeta) = star.locate(beam, x);
        let el = &star.elements[beam * star.ne + e];
        let pick = |c: &[f64]| {
            let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
            [c[a], c[a + 1], c[a + 2], c[b], c[b + 1], c[b + 2]]
        };
        let (qe, ve, ae) = (pick(self.q), pick(self.v), pick(self.qdd));
        let st = ElementState::new(el, &qe);
        let jac = st.jacobian(zeta);
        let conv = st.convective(zeta, &ve);
        let acc = [0, 1].map(|k| jac[k].iter().zip(&ae).map(|(j, a)| j * a).sum::<f64>() + conv[k]);
        let (angle, _, dangle) = st.angle(zeta);
        PointMotion {
            acc,
            // the element's angle is measured from its initial direction gamma0 (of e_x), whose
            // tangent angle in Eq. S3's sense is gamma0 + pi/2
            beta: star.gamma0[beam] + std::f64::consts::FRAC_PI_2 + angle,
            kappa: dangle / el.l0,
        }
    }

    /// G is node 0: its acceleration, and `psi` its cross-section's angle with its rates.
    fn junction(&self) -> JunctionMotion {
        JunctionMotion {
            acc: [self.qdd[0], self.qdd[1]],
            psi: self.star.gamma0[0] + std::f64::consts::FRAC_PI_2 + self.q[2],
            psi_d: self.v[2],
            psi_dd: self.qdd[2],
        }
    }

    fn slider(&self, i: usize) -> f64 {
        self.s[i]
    }

    fn force(&self, i: usize) -> f64 {
        self.fa[i]
    }
}
