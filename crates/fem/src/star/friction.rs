//! Friction in the sleeves and on the rails (`docs/friction.md` 3 and 8): the contact state of
//! each sleeve and slider (free, stuck, slipping) and what each adds to the Newton imbalance and
//! matrix. Absent (no `[friction]`), nothing here runs: the star is the frictionless one bit for
//! bit.
//!
//! **Sleeve i** acts on its centre's contact coordinate `xi_ic` (`crate::star::sleeve`), whose
//! equation is `sum_r (d Phi_r / d xi_ic) lambda_r + F_fi = 0` (Eq. F8): `F_fi` [N], the friction
//! force on the beam along its tangent, is the generalized force of friction on `xi_ic` with its
//! sign turned (its virtual work is `-F_fi delta xi_ic`).
//! - slipping with sign `s`: `F_fi = mu_k(v) L_i(lambda) s + c v` (Eqs. F5-F6), `v = xi_ic'`;
//!   the matrix gets `dF/dv gamma'` on the diagonal and `mu_k s dL/dlambda_r` in the row's
//!   multiplier columns (the slot group [`FRICTION_SLOTS`] per sleeve);
//! - stuck at `xi*`: `xi_ic = xi*` frozen (Eq. F9): its row of the matrix becomes the identity
//!   (diagonal 1, the multiplier columns cancelled by the slot group), the imbalance 0, and the
//!   integrator keeps `xi_ic = xi*`, `xi_ic' = xi_ic'' = 0`; the force the stick needs is then
//!   `F_fi = -sum_r (d Phi_r / d xi_ic) lambda_r` ([`Star::sleeve_friction_force`]).
//!
//! **Slider i** (direct problem; Eq. F4) adds `Fc s + b v` to its equation when slipping, and is
//! frozen like a stuck sleeve when stuck (its multiplier couplings in its own row set to 0).

use flexstar_model::{Friction, NormalLoad};

use super::*;

/// Slots per sleeve in the friction slot group: the centre coordinate's row against the
/// sleeve's [`ROWS`] multipliers.
pub(crate) const FRICTION_SLOTS: usize = ROWS;

pub(crate) use flexstar_model::friction_run::Contact;

/// The friction of a star and the contacts' states.
#[derive(Debug, Clone)]
pub(crate) struct StarFriction {
    pub law: Friction,
    /// Contacts of the sleeves and (direct problem) of the sliders.
    pub sleeves: [Contact; 3],
    pub rails: [Contact; 3],
}

impl StarFriction {
    /// The contacts at the start: those with a Coulomb limit stuck where they are when at rest
    /// (`|v| <=` `flexstar_model::friction_run::V_REST`), slipping along their velocity otherwise; viscous-only contacts slip,
    /// frictionless ones are free. `xi`, `xi_dot`: the sleeves' centre coordinates and speeds;
    /// `sliders`: `[s, s']` of each slider in the direct problem.
    pub fn start(law: Friction, xi: [f64; 3], xi_dot: [f64; 3], sliders: Option<[[f64; 2]; 3]>) -> Self {
        let sleeves = std::array::from_fn(|i| {
            let l = law.sleeve(i);
            Contact::start(l.mu_static > 0.0, l.c > 0.0, xi[i], xi_dot[i])
        });
        let rails = std::array::from_fn(|i| match sliders {
            Some(sl) => {
                let r = law.rail(i);
                Contact::start(r.fc > 0.0, r.b > 0.0, sl[i][0], sl[i][1])
            }
            None => Contact::Free,
        });
        StarFriction { law, sleeves, rails }
    }
}

impl Star {
    /// The normal and edge load `L_i` [N] that bounds sleeve i's friction (Eqs. F2-F3) at the
    /// coordinates `q` and the multipliers `lam` [N, N m] (unscaled), and its gradient in the
    /// sleeve's 7 multipliers: `|N|` with `N = n . (lambda_c + lambda_l + lambda_r)`, or
    /// `max(|N|, 2 |M| / Lp)` with `M = (Lp/2) n . (lambda_r - lambda_l) + lambda_7` (forces and
    /// couple on the sleeve; `n` the sleeve's normal).
    pub fn sleeve_load(&self, i: usize, q: &[f64], lam: &[f64], model: NormalLoad) -> (f64, [f64; ROWS]) {
        let ang = self.sleeve_angle(i, q);
        let n = [-ang.sin(), ang.cos()];
        let l = &lam[ROWS * i..ROWS * i + ROWS];
        let normal = n[0] * (l[0] + l[2] + l[4]) + n[1] * (l[1] + l[3] + l[5]);
        let sn = normal.signum();
        let by_normal = (
            normal.abs(),
            [sn * n[0], sn * n[1], sn * n[0], sn * n[1], sn * n[0], sn * n[1], 0.0],
        );
        if model == NormalLoad::Normal {
            return by_normal;
        }
        let lp = self.beam(i).sleeve_length;
        let moment = 0.5 * lp * (n[0] * (l[4] - l[2]) + n[1] * (l[5] - l[3])) + l[6];
        let edges = 2.0 * moment.abs() / lp;
        if edges <= by_normal.0 {
            return by_normal;
        }
        let sm = moment.signum();
        (
            edges,
            [0.0, 0.0, -sm * n[0], -sm * n[1], sm * n[0], sm * n[1], 2.0 * sm / lp],
        )
    }

    /// The friction force on beam i along its tangent at the sleeve [N] at a converged state
    /// (Eq. F8): `-sum_r (d Phi_r / d xi_ic) lambda_r` over the centre's rows; in slip the law's
    /// force, in stick the force the stick needs.
    pub fn sleeve_friction_force(&self, i: usize, q: &[f64], lam: &[f64], pins: &Pins) -> f64 {
        let (e, z) = self.locate(i, q[self.xi(i, 0)]);
        let el = &self.elements[i * self.ne + e];
        let st = ElementState::new(el, &self.element_q(el, q));
        let na = self.node(i, e);
        let node_a = [q[3 * na], q[3 * na + 1]];
        let psi = q[self.psi(i)];
        -(0..ROWS)
            .filter(|&r| ROW_POINT[r] == 0)
            .map(|r| self.row_terms(&st, node_a, i, psi, pins.p[i], r, z).2 * lam[ROWS * i + r])
            .sum::<f64>()
    }

    /// Sleeve i's friction in the imbalance and, with `matrix`, its slots (module doc), after
    /// [`Star::sleeve_rows`] wrote the sleeve's constraint rows (their contact derivatives are
    /// read back to cancel them in a stuck sleeve's row).
    pub(super) fn sleeve_friction_rows(&mut self, i: usize, it: &Iterate, fac: Factors, res: &mut [f64], matrix: bool) {
        let Some(fr) = &self.friction else {
            return;
        };
        let (contact, law, model) = (fr.sleeves[i], fr.law.sleeve(i), fr.law.model);
        let xc = self.xi(i, 0);
        let (diag, cols) = (self.off_psi + 4 * i + 1, self.off_fr + FRICTION_SLOTS * i);
        match contact {
            Contact::Free => {}
            Contact::Stuck(_) => {
                res[xc] = 0.0;
                if matrix {
                    self.vals[diag] = 1.0;
                    for r in 0..ROWS {
                        let gxi = self.vals[self.off_con + (ROWS * i + r) * 2 * self.ncol_c + self.ncol_c - 2];
                        self.vals[cols + r] = if ROW_POINT[r] == 0 { -gxi } else { 0.0 };
                    }
                }
            }
            Contact::Slip(sign) => {
                // the load is homogeneous of degree 1 in the multipliers: that of the scaled ones
                // `nu = cf lambda` over cf, with the same gradient
                let cf = fac.cf;
                let (load_nu, grad) = self.sleeve_load(i, it.q, it.lam, model);
                let load = load_nu / cf;
                let v = it.v[xc];
                res[xc] += cf * law.slip_force(v, load, sign);
                if matrix {
                    self.vals[diag] = fac.cv * (law.kinetic_slope(v) * load * sign + law.c);
                    let mu = law.kinetic(v) * sign;
                    for r in 0..ROWS {
                        self.vals[cols + r] = mu * grad[r];
                    }
                }
            }
        }
    }

    /// Slider i's rail friction in its equation of the direct problem (module doc), after
    /// [`Star::assemble_sliders`] wrote the frictionless row.
    pub(super) fn rail_friction_rows(&mut self, i: usize, v: &[f64], fac: Factors, res: &mut [f64], matrix: bool) {
        let Some(fr) = &self.friction else {
            return;
        };
        let (contact, law) = (fr.rails[i], fr.law.rail(i));
        let si = self.slider(i);
        let base = self.off_sl + SLIDER_SLOTS * i;
        match contact {
            Contact::Free => {}
            Contact::Stuck(_) => {
                res[si] = 0.0;
                if matrix {
                    self.vals[base] = 1.0;
                    for r in 0..6 {
                        self.vals[base + 2 + 2 * r] = 0.0;
                    }
                }
            }
            Contact::Slip(sign) => {
                res[si] += fac.cf * (law.fc * sign + law.b * v[si]);
                if matrix {
                    self.vals[base] += fac.cv * law.b;
                }
            }
        }
    }

    /// The frozen coordinates of the stuck contacts: `(index, value)` (sleeve centres, sliders).
    pub fn stuck_coordinates(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        let fr = self.friction.as_ref();
        let sleeves = (0..3).filter_map(move |i| fr.and_then(|f| f.sleeves[i].stuck()).map(|at| (self.xi(i, 0), at)));
        let rails = (0..3).filter_map(move |i| fr.and_then(|f| f.rails[i].stuck()).map(|at| (self.slider(i), at)));
        sleeves.chain(rails)
    }

    /// The force slider i's rail must hold while the slider is stuck [N] (along `+u_i`, the
    /// force on the slider the rail's friction balances): `Fa_i + u_i . F_i + (mpp + mpa)_i g . u_i`
    /// with `Fa_i` the law's force and `F_i` the pin force (the slider equation at rest).
    pub fn rail_stick_force(&self, i: usize, fa: f64, pin_force: [f64; 2]) -> f64 {
        let u = self.slider_direction(i);
        let weight = if self.attached.weighs() {
            self.beam(i).sleeve_mass * self.gravity_along(i)
        } else {
            0.0
        };
        fa + u[0] * pin_force[0] + u[1] * pin_force[1] + weight
    }
}
