//! Friction in the sleeves in the AMM's step (`docs/friction.md` 9.1, Eqs. F11-F16 and their
//! full-model forms F19-F23). Absent (no `[friction]`), nothing here runs: every hook in
//! `system` is guarded by `System::friction` being `Some`, and the run is the frictionless one
//! bit for bit.
//!
//! Sleeve i's material coordinate is `xi_i = xp_i - u_i + f_i(x_c)` (Eq. F19 [m]; the
//! foreshortening shift `f` of `docs/amm.md` 12.11, zero in the paper's model), its sliding speed
//! `v_si = xp_i' - u_i' + g_i . alpha_i'` [m/s]; the friction force `F_fi` [N] on beam i along its
//! axis at the sleeve is the generalized force `F_fi b_i`, `b_i = e_ui - g_i` (Eq. F20: `+1` on
//! `u_i`, `-g_i` on the kept modes of `alpha_i`, the axial force `F_fi` in the span between G and
//! the sleeve acting on its foreshortening).
//! - slipping (sign `s`): `F_fi = mu_k(v^) s (l_i . lambda) / (1 + mu_k(v^) s sigma thp^) + c
//!   (v^_si - gamma' u_i'')` (Eqs. F14, F22), the load's linear form `l_i` over the sleeve's
//!   multipliers `[Fp, FR, FL, Mp]` ([`load`], Eq. F13) with its signs from the previous step,
//!   divided by the tilt of the sleeve's axis (Eq. F21: the normal load is the multipliers' sum
//!   less the friction's component `thp F_fi` across the beam); the viscous part on the
//!   arrowhead's u diagonal (`BeamModel::u_drag`) and in the forcing (its alpha part at the
//!   predicted speed), the Coulomb part as the rank-3 update of the Schur complement (Eq. F15
//!   with `b_i`, [`System::add_friction_to_schur`]) and in the substitution;
//! - stuck at `xi*`: the row `u_i - g^_i . alpha_i - xp_i(t) + xi* + f^_i + (xp_i / EA_i) F_ti = 0`
//!   (Eqs. F16, F23), whose multiplier is the force the stick needs; a sleeve not stuck keeps
//!   that row as the identity (multiplier 0).

use flexstar_kinematics::RigidState;
use flexstar_model::{Contact, Friction, NormalLoad};

use crate::sleeve::ShiftAt;
use crate::system::{BeamRows, System, NONE};

/// The load that bounds a sleeve's friction (Eqs. F13, F21, F3) at its multipliers `lam` =
/// `[Fp, FR, FL, Mp]` [N, N, N, N m] (`hp` = Lp / 2 [m]) with the friction's component across the
/// beam `tangential = thp F_f` [N] (Eq. F21), and the gradient in the multipliers (the load less
/// that component is homogeneous of degree 1 in them: `load = gradient . lam` when `tangential`
/// is 0): `|N|`, `N = Fp + FR + FL - tangential`, or with `model = "edges"` `max(|N|, |M| / hp)`,
/// `M = (FR - FL) hp - Mp` the sleeve's couple on the beam.
pub(crate) fn load(model: NormalLoad, hp: f64, lam: [f64; 4], tangential: f64) -> (f64, [f64; 4]) {
    let n = lam[0] + lam[1] + lam[2] - tangential;
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
    /// The stick rows' compliance `xp_i / (EA_i beta')` of the step (0 unless stuck).
    compliance: [f64; 3],
    /// Whether each stick row is in use (its sleeve stuck, in a step).
    active: [bool; 3],
    // the step's terms: the rigid state and rates kept by [`System::predict_friction`], the
    // rest set by [`System::friction_terms`] once the sleeve rows are at the predictor
    /// `mu_k s l_i / (1 + mu_k s sigma thp^)` over `[Fp, FR, FL, Mp]` (0 unless slipping)
    /// [-, 1/m for Mp].
    coef: [[f64; 4]; 3],
    /// The viscous coefficient in use, `c_i` while slipping, else 0 [N s/m].
    drag: [f64; 3],
    /// The predicted sliding speed `xp_i' - u^_i' + g_i . alpha^_i'` [m/s].
    v_pred: [f64; 3],
    /// The predicted sleeve rotations `thp^_i` [rad] (the tilt of Eq. F21).
    thp: [f64; 3],
    /// `xp_i`, `xp_i'`, `xp_i''` of the step's rigid state [m, m/s, m/s^2].
    xp: [[f64; 3]; 3],
    /// beta' [s^2] and gamma' [s] of the step.
    bp: f64,
    gp: f64,
    /// The predicted rates of the step, 3 (N + 2).
    vhat: Vec<f64>,
    /// Workspace, N + 2.
    tmp: Vec<f64>,
}

impl SleeveFriction {
    /// The friction `law` of a system whose sleeve rows are `rows`, stick rows `stick`, half
    /// sleeve lengths `hp`; the contacts start free ([`System::start_contacts`] sets them).
    /// `ea`: the beams' axial stiffness [N]; `nb`: a beam's coordinates, N + 2.
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
            active: [false; 3],
            coef: [[0.0; 4]; 3],
            drag: [0.0; 3],
            v_pred: [0.0; 3],
            thp: [0.0; 3],
            xp: [[0.0; 3]; 3],
            bp: 0.0,
            gp: 0.0,
            vhat: vec![0.0; 3 * nb],
            tmp: vec![0.0; nb],
        }
    }

    /// Sleeve i's load (Eqs. F13, F21) at the multipliers `lam` [N] with the friction force
    /// `force` [N] on the beam (the tilt of the step's predicted sleeve rotation).
    pub(crate) fn load_at(&self, i: usize, lam: &[f64], force: f64) -> f64 {
        load(
            self.law.model,
            self.hp[i],
            self.rows[i].map(|r| lam[r]),
            self.thp[i] * force,
        )
        .0
    }

    /// Slipping sleeve i's Coulomb coefficients over `[Fp, FR, FL, Mp]` (Eqs. F14, F22: `mu_k(v^)
    /// s l_i / (1 + mu_k s sigma thp^)`, the load's signs from the last multipliers `lam`) and its
    /// viscous coefficient `c` [N s/m]; zeros unless slipping. Needs the step's `v_pred`, `thp`.
    fn slip_terms(&self, i: usize, lam: &[f64]) -> ([f64; 4], f64) {
        let Contact::Slip(s) = self.contacts[i] else {
            return ([0.0; 4], 0.0);
        };
        let law = self.law.sleeve(i);
        let (_, form) = load(self.law.model, self.hp[i], self.rows[i].map(|r| lam[r]), 0.0);
        let mu = law.kinetic(self.v_pred[i]) * s;
        // Eq. F22: the normal branch's load less the friction's own component across the beam,
        // thp F_f (form[0] is the load's sign on that branch, 0 on the "edges" branch)
        let tilt = 1.0 / (1.0 + mu * form[0] * self.thp[i]);
        (form.map(|f| mu * f * tilt), law.c)
    }

    /// Sleeve i's stick row on its beam's rows `beam` (Eqs. F16, F23): stuck at `xi*` in a step
    /// (`bp > 0`), u coefficient 1, alpha vector `-g^` (the full model's `shift`), value
    /// `xi* - xp(t) + f^` and compliance `xp / EA`; else empty (its multiplier 0), and so at the
    /// consistent start and at an event (`bp = 0`), where a stuck sleeve's force is that of its
    /// compliance at the state, not an unknown (Eq. F26).
    fn set_stick_row(&mut self, i: usize, beam: &mut BeamRows, shift: Option<&ShiftAt>) {
        let k = (beam.ids.iter())
            .position(|&g| g == self.stick[i])
            .expect("the stick row is beam i's");
        let stuck = match self.contacts[i] {
            Contact::Stuck(at) if self.bp > 0.0 => Some(at),
            _ => None,
        };
        let f_hat = shift.map_or(0.0, |s| s.f);
        let xp = self.xp[i][0];
        let (c, value, compliance) = match stuck {
            Some(at) => (1.0, at - xp + f_hat, xp / self.ea[i] / self.bp),
            None => (0.0, 0.0, 0.0),
        };
        self.active[i] = stuck.is_some();
        (beam.cu[k], beam.gu[k], beam.gv[k], beam.sc[k]) = (c, c, value, c);
        if beam.stick_live {
            beam.stick.iter_mut().for_each(|x| *x = 0.0);
        }
        beam.stick_live = false;
        if let (Some(s), Some(_)) = (shift, stuck) {
            for (&j, g) in s.kept.iter().zip(s.g) {
                beam.stick[j] = -g;
            }
            beam.stick_live = true;
        }
        self.compliance[i] = compliance;
    }
}

/// `g . alpha'` of a beam's foreshortening at its sleeve (`shift`; 0 in the paper's model) for
/// its modal rates `rates` [m/s]: the shift's part of the sliding speed (Eq. F19).
fn shift_rate(shift: Option<&ShiftAt>, rates: &[f64]) -> f64 {
    shift.map_or(0.0, |s| s.kept.iter().zip(s.g).map(|(&j, g)| g * rates[j]).sum())
}

impl System {
    /// Sleeve i's material coordinate `xi_i = xp_i - u_i + f_i(xp_i - u_i)` [m] (Eq. F19; the
    /// shift f of the full model, `docs/amm.md` 12.11, one evaluation as Eq. S1) at the rigid
    /// state `st` and the coordinates `q`.
    pub(crate) fn sliding_coordinate(&self, i: usize, st: &RigidState, q: &[f64]) -> f64 {
        let (o, nm) = (i * self.nb, self.nm);
        let x = st.xp[i].v - q[o + nm];
        x + self.sleeves.shift_of(i, x, &q[o..o + nm])
    }

    /// Sleeve i's sliding speed `v_si = xp_i' - u_i' + g_i . alpha_i'` [m/s] (Eq. F19, g at the
    /// last update of the sleeve rows) at `st` and the rates `v`.
    pub(crate) fn sliding_speed(&self, i: usize, st: &RigidState, v: &[f64]) -> f64 {
        let (o, nm) = (i * self.nb, self.nm);
        let shift = self.sleeves.shift_at_update(i);
        st.xp[i].d1 - v[o + nm] + shift_rate(shift.as_ref(), &v[o..o + nm])
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

    /// Keep what the step's friction terms need of the rigid state `st` (the sleeves' `xp`),
    /// the predicted rates `vhat` and `bp` = beta' [s^2], `gp` = gamma' [s]; call before
    /// [`System::prepare`], which sets the terms ([`System::friction_terms`]) once the sleeve
    /// rows are at the predictor.
    pub(crate) fn predict_friction(&mut self, st: &RigidState, vhat: &[f64], (bp, gp): (f64, f64)) {
        let Some(fr) = self.friction.as_mut() else {
            return;
        };
        (fr.bp, fr.gp) = (bp, gp);
        fr.vhat.copy_from_slice(vhat);
        for i in 0..3 {
            fr.xp[i] = [st.xp[i].v, st.xp[i].d1, st.xp[i].d2];
        }
    }

    /// The step's friction terms (module doc), in [`System::prepare`] after the sleeve rows were
    /// set at the predictor `qhat` (their foreshortening's `f^`, `g^`): the predicted sliding
    /// speeds (Eq. F19), each slipping sleeve's `mu_k(v^) s l_i / (1 + mu_k s sigma thp^)` with
    /// the load's signs from the last multipliers `self.lam` (Eqs. F14, F22), its viscous
    /// coefficient (`c gamma'` on its arrowhead's u diagonal), and each stick row (Eqs. F16,
    /// F23: u coefficient 1, alpha vector `-g^`, value `u^ - f^ - xp(t) + xi*` and compliance
    /// `xp / EA` when stuck, else empty). In the consistent start (`bp = 0`) a stuck sleeve's
    /// row is empty: its force, that of the compliance, is 0 where it sticks.
    pub(crate) fn friction_terms(&mut self, qhat: &[f64]) {
        let (nm, nb) = (self.nm, self.nb);
        let (Some(fr), lam, beams, sleeves) = (self.friction.as_mut(), &self.lam, &mut self.beams, &self.sleeves)
        else {
            return;
        };
        for (i, beam) in beams.iter_mut().enumerate() {
            let o = i * nb;
            let shift = sleeves.shift_at_update(i);
            fr.v_pred[i] = fr.xp[i][1] - fr.vhat[o + nm] + shift_rate(shift.as_ref(), &fr.vhat[o..o + nm]);
            fr.thp[i] = qhat[o + nm + 1];
            (fr.coef[i], fr.drag[i]) = fr.slip_terms(i, lam);
            fr.set_stick_row(i, beam, shift.as_ref());
        }
        for (i, b) in self.bm.iter_mut().enumerate() {
            b.u_drag = fr.drag[i] * fr.gp;
        }
    }

    /// All sleeves free (the static equilibria under gravity after a run, which friction does
    /// not enter: `static_start`).
    pub(crate) fn release_contacts(&mut self) {
        if let Some(fr) = self.friction.as_mut() {
            fr.contacts = [Contact::Free; 3];
        }
    }

    /// The direction `b_i` of sleeve i's friction force among beam i's coordinates (Eq. F20)
    /// into `x` (N + 2): `+1` on `u_i`, `-g_i` on the kept modes (full model), 0 elsewhere.
    pub(crate) fn friction_direction(&self, i: usize, x: &mut [f64]) {
        x.iter_mut().for_each(|v| *v = 0.0);
        x[self.nm] = 1.0;
        if let Some(s) = self.sleeves.shift_at_update(i) {
            for (&j, g) in s.kept.iter().zip(s.g) {
                x[j] = -g;
            }
        }
    }

    /// Eq. F15 on the assembled Schur complement: the stick rows of sleeves not stuck made the
    /// identity, those of stuck ones given their compliance `xp / (EA beta')` (Eq. F16), and
    /// each slipping sleeve's Coulomb term, `(C S'^-1 b_i) f_i^T` against its four columns
    /// (`b_i` of Eq. F20; `S'^-1` from the arrowhead, beam 1 with the payload's correction).
    pub(crate) fn add_friction_to_schur(&mut self) {
        let Some(mut fr) = self.friction.take() else {
            return;
        };
        let (nm, m) = (self.nm, self.rows.len());
        for i in 0..3 {
            let k = fr.stick[i];
            if fr.active[i] {
                self.a[k * m + k] += fr.compliance[i];
            } else {
                self.a[k * m + k] = 1.0;
            }
            if fr.coef[i] == [0.0; 4] {
                continue;
            }
            let mut x = std::mem::take(&mut fr.tmp);
            self.friction_direction(i, &mut x);
            self.beam(i).arrow_solve(&mut x);
            if i == 0 {
                self.payload_correct(&mut x);
            }
            let beam = &self.beams[i];
            for (k, &g) in beam.ids.iter().enumerate() {
                let mut h = beam.cu[k] * x[nm] + beam.ct[k] * x[nm + 1];
                // a row without an alpha part, or a stick row not stuck (its vector zero)
                if beam.basis[k] != NONE && beam.sc[k] != 0.0 {
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

    /// The viscous friction's part of the forcing, `c_i (xp_i' - u^_i' + g_i . alpha^_i') b_i` on
    /// each slipping beam (Eqs. F14, F20; its alpha part at the predicted speed).
    pub(crate) fn friction_forcing(&mut self) {
        let Some(fr) = &self.friction else {
            return;
        };
        for i in 0..3 {
            if fr.drag[i] != 0.0 {
                let (o, f) = (i * self.nb, fr.drag[i] * fr.v_pred[i]);
                self.resid[o + self.nm] += f;
                if let Some(s) = self.sleeves.shift_at_update(i) {
                    for (&j, g) in s.kept.iter().zip(s.g) {
                        self.resid[o + j] -= f * g;
                    }
                }
            }
        }
    }

    /// The Coulomb friction `(f_i . lambda) b_i` of the multipliers `lam` added to each beam's
    /// rows of `x` (the substitution's `S'^-1 (r + C^T lambda + sum b_i f_i . lambda)`, Eqs. F15,
    /// F20).
    pub(crate) fn add_coulomb(&self, lam: &[f64], x: &mut [f64]) {
        let Some(fr) = &self.friction else {
            return;
        };
        for i in 0..3 {
            if fr.coef[i] != [0.0; 4] {
                let f: f64 = fr.rows[i].iter().zip(fr.coef[i]).map(|(r, c)| c * lam[*r]).sum();
                let o = i * self.nb;
                x[o + self.nm] += f;
                if let Some(s) = self.sleeves.shift_at_update(i) {
                    for (&j, g) in s.kept.iter().zip(s.g) {
                        x[o + j] -= f * g;
                    }
                }
            }
        }
    }

    /// The friction force on beam i along its axis at the sleeve [N] for the multipliers `lam` and the axial
    /// acceleration `udd` of the step: slipping, Eqs. F14, F22 (`constant`: with the predictor's
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
                let (l, g) = load(model, hp, lam, 0.0);
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
