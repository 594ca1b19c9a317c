//! Friction in the sleeves in the AMM's step (`docs/friction.md` 9.1, Eqs. F11-F16). Absent
//! (no `[friction]`), nothing here runs: every hook in `system` is guarded by
//! `System::friction` being `Some`, and the run is the frictionless one bit for bit.
//!
//! Sleeve i's material coordinate is `xi_i = xp_i - u_i` (Eq. F11, [m]), its sliding speed
//! `v_si = xp_i' - u_i'` [m/s]; the friction force `F_fi` [N] on beam i along `e_xi` is the
//! generalized force `+F_fi` on `u_i`.
//! - slipping (sign `s`): `F_fi = mu_k(v^) s (l_i . lambda) + c (xp_i' - u^_i' - gamma' u_i'')`
//!   (Eq. F14), the load's linear form `l_i` over the sleeve's multipliers `[Fp, FR, FL, Mp]`
//!   ([`load`], Eq. F13) with its signs from the previous step; the viscous part on the
//!   arrowhead's u diagonal (`BeamModel::u_drag`) and in the forcing, the Coulomb part as the
//!   rank-3 update of the Schur complement (Eq. F15, [`System::add_friction_to_schur`]) and in
//!   the substitution;
//! - stuck at `xi*`: the row `u_i - xp_i(t) + xi* = 0` (Eq. F16), whose multiplier is the force
//!   the stick needs; a sleeve not stuck keeps that row as the identity (multiplier 0).

use flexstar_kinematics::RigidState;
use flexstar_model::{Contact, Friction, NormalLoad};

use crate::system::{System, NONE};

/// The load that bounds a sleeve's friction (Eqs. F13, F3) at its multipliers `lam` =
/// `[Fp, FR, FL, Mp]` [N, N, N, N m] (`hp` = Lp / 2 [m]), and its gradient in them (the load
/// is homogeneous of degree 1: `load = gradient . lam`): `|N|`, `N = Fp + FR + FL`, or with
/// `model = "edges"` `max(|N|, |M| / hp)`, `M = (FR - FL) hp - Mp` the sleeve's couple on the beam.
pub(crate) fn load(model: NormalLoad, hp: f64, lam: [f64; 4]) -> (f64, [f64; 4]) {
    let n = lam[0] + lam[1] + lam[2];
    let sn = if n < 0.0 { -1.0 } else { 1.0 };
    let normal = (n.abs(), [sn, sn, sn, 0.0]);
    if model == NormalLoad::Normal {
        return normal;
    }
    let m = (lam[1] - lam[2]) * hp - lam[3];
    let edges = m.abs() / hp;
    if edges <= normal.0 {
        return normal;
    }
    let sm = if m < 0.0 { -1.0 } else { 1.0 };
    (edges, [0.0, sm, -sm, -sm / hp])
}

/// The sleeves' friction of a system and the step's terms (module doc).
#[derive(Debug, Clone)]
pub(crate) struct SleeveFriction {
    pub(crate) law: Friction,
    /// The state of each sleeve on its beam.
    pub(crate) contacts: [Contact; 3],
    /// Global indices of sleeve i's rows `[Fp, FR, FL, Mp]` (Eqs. 41-43).
    pub(crate) rows: [[usize; 4]; 3],
    /// Global index of sleeve i's stick row (Eq. F16).
    pub(crate) stick: [usize; 3],
    /// Half sleeve lengths Lp_i / 2 [m].
    pub(crate) hp: [f64; 3],
    /// The beams' axial stiffness EA_i [N] (the stick row's compliance, Eq. F16).
    ea: [f64; 3],
    /// The stick rows' compliance `xp_i / EA_i` of the step [m/N] (0 unless stuck).
    compliance: [f64; 3],
    // the step's terms, set by [`System::predict_friction`]
    /// `mu_k s l_i` over `[Fp, FR, FL, Mp]` (0 unless slipping) [-, 1/m for Mp].
    coef: [[f64; 4]; 3],
    /// The viscous coefficient in use, `c_i` while slipping, else 0 [N s/m].
    drag: [f64; 3],
    /// The predicted sliding speed `xp_i' - u^_i'` [m/s].
    v_pred: [f64; 3],
    /// `xp_i`, `xp_i'`, `xp_i''` of the step's rigid state [m, m/s, m/s^2].
    xp: [[f64; 3]; 3],
    /// gamma' of the step [s].
    gp: f64,
    /// Workspace, N + 2.
    tmp: Vec<f64>,
}

impl SleeveFriction {
    /// The friction `law` of a system whose sleeve rows are `rows`, stick rows `stick`, half
    /// sleeve lengths `hp`; the contacts start free ([`System::start_contacts`] sets them).
    /// `ea`: the beams' axial stiffness [N].
    pub(crate) fn new(
        law: Friction,
        (rows, stick): ([[usize; 4]; 3], [usize; 3]),
        hp: [f64; 3],
        ea: [f64; 3],
        nb: usize,
    ) -> Self {
        SleeveFriction {
            law,
            contacts: [Contact::Free; 3],
            rows,
            stick,
            hp,
            ea,
            compliance: [0.0; 3],
            coef: [[0.0; 4]; 3],
            drag: [0.0; 3],
            v_pred: [0.0; 3],
            xp: [[0.0; 3]; 3],
            gp: 0.0,
            tmp: vec![0.0; nb],
        }
    }

    /// Sleeve i's load (Eq. F13) at the multipliers `lam` [N].
    pub(crate) fn load_at(&self, i: usize, lam: &[f64]) -> f64 {
        load(self.law.model, self.hp[i], self.rows[i].map(|r| lam[r])).0
    }
}

impl System {
    /// Sleeve i's material coordinate `xi_i = xp_i - u_i` [m] (Eq. F11) at the rigid state `st`
    /// and the coordinates `q`.
    pub(crate) fn sliding_coordinate(&self, i: usize, st: &RigidState, q: &[f64]) -> f64 {
        st.xp[i].v - q[i * self.nb + self.nm]
    }

    /// Sleeve i's sliding speed `v_si = xp_i' - u_i'` [m/s] (Eq. F11) at `st` and the rates `v`.
    pub(crate) fn sliding_speed(&self, i: usize, st: &RigidState, v: &[f64]) -> f64 {
        st.xp[i].d1 - v[i * self.nb + self.nm]
    }

    /// The contacts at the start of a run (`flexstar_model::Contact::start`) at the rigid state
    /// `st` with the star at rest elastically (`q`, `v` its coordinates and rates).
    pub(crate) fn start_contacts(&mut self, st: &RigidState, q: &[f64], v: &[f64]) {
        let xi: [f64; 3] = std::array::from_fn(|i| self.sliding_coordinate(i, st, q));
        let vs: [f64; 3] = std::array::from_fn(|i| self.sliding_speed(i, st, v));
        if let Some(fr) = self.friction.as_mut() {
            fr.contacts = std::array::from_fn(|i| {
                let l = fr.law.sleeve(i);
                Contact::start(l.mu_static > 0.0, l.c > 0.0, xi[i], vs[i])
            });
        }
    }

    /// The step's friction terms (module doc) before [`System::prepare`]: each slipping sleeve's
    /// `mu_k(v^) s l_i` with the load's signs from the last multipliers `self.lam` and the
    /// Stribeck coefficient at the predicted sliding speed, its viscous coefficient, and each
    /// stick row (Eq. F16: u coefficient 1, value `u^ - xp(t) + xi*` and compliance `xp / EA`
    /// when stuck, else empty) at the rigid state `st`; `vhat` the predicted rates, `bp`, `gp` =
    /// beta' [s^2], gamma' [s]. In the consistent start (`bp = 0`) a stuck sleeve's row is empty:
    /// its force, that of the compliance, is 0 where it sticks.
    pub(crate) fn predict_friction(&mut self, st: &RigidState, vhat: &[f64], (bp, gp): (f64, f64)) {
        let (nm, nb) = (self.nm, self.nb);
        let (Some(fr), lam, beams) = (self.friction.as_mut(), &self.lam, &mut self.beams) else {
            return;
        };
        fr.gp = gp;
        for i in 0..3 {
            let xp = [st.xp[i].v, st.xp[i].d1, st.xp[i].d2];
            fr.xp[i] = xp;
            let v = xp[1] - vhat[i * nb + nm];
            fr.v_pred[i] = v;
            let law = fr.law.sleeve(i);
            (fr.coef[i], fr.drag[i]) = match fr.contacts[i] {
                Contact::Slip(s) => {
                    let (_, form) = load(fr.law.model, fr.hp[i], fr.rows[i].map(|r| lam[r]));
                    let mu = law.kinetic(v) * s;
                    (form.map(|f| mu * f), law.c)
                }
                _ => ([0.0; 4], 0.0),
            };
            let beam = &mut beams[i];
            let k = (beam.ids.iter())
                .position(|&g| g == fr.stick[i])
                .expect("the stick row is beam i's");
            let (c, value, compliance) = match fr.contacts[i] {
                Contact::Stuck(at) if bp > 0.0 => (1.0, at - xp[0], xp[0] / fr.ea[i] / bp),
                _ => (0.0, 0.0, 0.0),
            };
            (beam.cu[k], beam.gu[k], beam.gv[k]) = (c, c, value);
            fr.compliance[i] = compliance;
        }
    }

    /// All sleeves free (the static equilibria under gravity after a run, which friction does
    /// not enter: `static_start`).
    pub(crate) fn release_contacts(&mut self) {
        if let Some(fr) = self.friction.as_mut() {
            fr.contacts = [Contact::Free; 3];
        }
    }

    /// The viscous friction on each beam's arrowhead, `c_i gamma'` on its u diagonal (Eq. F14),
    /// before the arrowheads are factored; none without friction. Beams share an arrowhead only
    /// without viscous sleeve friction (`crate::star::Star::new`).
    pub(crate) fn set_friction_drag(&mut self, gp: f64) {
        let Some(fr) = &self.friction else {
            return;
        };
        for (i, b) in self.bm.iter_mut().enumerate() {
            b.u_drag = fr.drag[i] * gp;
        }
    }

    /// Eq. F15 on the assembled Schur complement: the stick rows of sleeves not stuck made the
    /// identity, those of stuck ones given their compliance `xp / (EA beta')` (Eq. F16), and each slipping sleeve's Coulomb term, `(C S'^-1 e_ui) f_i^T` against its four
    /// columns (`C S'^-1 e_ui` from the arrowhead, beam 1 with the payload's correction).
    pub(crate) fn add_friction_to_schur(&mut self) {
        let Some(mut fr) = self.friction.take() else {
            return;
        };
        let (nm, m) = (self.nm, self.rows.len());
        for i in 0..3 {
            let k = fr.stick[i];
            if fr.compliance[i] > 0.0 {
                self.a[k * m + k] += fr.compliance[i];
            } else {
                self.a[k * m + k] = 1.0;
            }
            if fr.coef[i] == [0.0; 4] {
                continue;
            }
            let mut x = std::mem::take(&mut fr.tmp);
            x.iter_mut().for_each(|v| *v = 0.0);
            x[nm] = 1.0;
            self.beam(i).arrow_solve(&mut x);
            if i == 0 {
                self.payload_correct(&mut x);
            }
            let beam = &self.beams[i];
            for (k, &g) in beam.ids.iter().enumerate() {
                let mut h = beam.cu[k] * x[nm] + beam.ct[k] * x[nm + 1];
                if beam.basis[k] != NONE {
                    h += beam.sc[k] * crate::modes::dot(self.basis(i, beam, beam.basis[k]), &x[..nm]);
                }
                for (col, f) in fr.rows[i].iter().zip(fr.coef[i]) {
                    self.a[g * m + col] += h * f;
                }
            }
            fr.tmp = x;
        }
        self.friction = Some(fr);
    }

    /// The viscous friction's part of the forcing, `c_i (xp_i' - u^_i')` on each slipping
    /// beam's u row (Eq. F14).
    pub(crate) fn friction_forcing(&mut self) {
        let Some(fr) = &self.friction else {
            return;
        };
        for i in 0..3 {
            if fr.drag[i] != 0.0 {
                self.resid[i * self.nb + self.nm] += fr.drag[i] * fr.v_pred[i];
            }
        }
    }

    /// The Coulomb friction `f_i . lambda` of the multipliers `lam` added to each beam's u row of
    /// `x` (the substitution's `S'^-1 (r + C^T lambda + sum e_ui f_i . lambda)`, Eq. F15).
    pub(crate) fn add_coulomb(&self, lam: &[f64], x: &mut [f64]) {
        let Some(fr) = &self.friction else {
            return;
        };
        for i in 0..3 {
            if fr.coef[i] != [0.0; 4] {
                let f: f64 = fr.rows[i].iter().zip(fr.coef[i]).map(|(r, c)| c * lam[*r]).sum();
                x[i * self.nb + self.nm] += f;
            }
        }
    }

    /// The friction force on beam i along `e_xi` [N] for the multipliers `lam` and the axial
    /// acceleration `udd` of the step: slipping, Eq. F14 (`constant`: with the predictor's
    /// part `c v^`; without it, the change along a change of `lam` and `udd`, for the direct
    /// problem's sensitivities); stuck, the stick row's multiplier (Eq. F16); 0 when free or
    /// without friction.
    pub(crate) fn sleeve_friction_force(&self, i: usize, lam: &[f64], udd: f64, constant: bool) -> f64 {
        let Some(fr) = &self.friction else {
            return 0.0;
        };
        match fr.contacts[i] {
            Contact::Free => 0.0,
            Contact::Stuck(_) => lam[fr.stick[i]],
            Contact::Slip(_) => {
                let coulomb: f64 = fr.rows[i].iter().zip(fr.coef[i]).map(|(r, c)| c * lam[*r]).sum();
                let v = if constant { fr.v_pred[i] } else { 0.0 } - fr.gp * udd;
                coulomb + fr.drag[i] * v
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_load_is_its_gradient_times_the_multipliers() {
        // F13 and F3 against the edge loads written out: N_R,L = N/2 +- M/Lp
        let hp = 0.05;
        for lam in [[3.0, -1.0, 2.0, 0.1], [0.5, 4.0, -4.2, 0.02], [-1.0, 0.2, 0.1, -0.3]] {
            for model in [NormalLoad::Normal, NormalLoad::Edges] {
                let (l, g) = load(model, hp, lam);
                let by_gradient: f64 = g.iter().zip(lam).map(|(a, b)| a * b).sum();
                assert!((l - by_gradient).abs() < 1e-14 * (1.0 + l));
                let n = lam[0] + lam[1] + lam[2];
                let m = (lam[1] - lam[2]) * hp - lam[3];
                let expect = match model {
                    NormalLoad::Normal => n.abs(),
                    NormalLoad::Edges => (n / 2.0 + m / (2.0 * hp)).abs() + (n / 2.0 - m / (2.0 * hp)).abs(),
                };
                assert!((l - expect).abs() < 1e-12, "{model:?} {lam:?}: {l} vs {expect}");
            }
        }
    }
}
