//! Every quantity flexstar writes as a column of a result file, declared once: its name, its unit
//! and what it means (`docs/architecture.md`, "Outputs").
//!
//! A quantity of each beam, sleeve or slider is declared once with `{i}` in its name (`w{i}G`:
//! the columns `w1G`, `w2G`, `w3G`). The solvers and the kinematics keep their own column
//! *order* (a file contract: [`crate::response::RESPONSE_HEADER`], the AMM's `EXTRA_COLUMNS`,
//! the FEM's columns); every name they write must be declared here (tests), the sidecar's
//! `column_units` is drawn from here, and the column index of `docs/outputs.md` is generated
//! from [`QUANTITIES`] (a test keeps it equal: [`column_index_markdown`]). A new output is one
//! declaration here, its name in the writer's column list and its evaluation in each solver.

/// One output quantity (see the module doc). Units are SI, as `docs/outputs.md` writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quantity {
    /// Column name; `{i}` stands for the beam, sleeve or slider number 1..3.
    pub name: &'static str,
    /// Unit (`m`, `N m`, `m/s^2`, ...).
    pub unit: &'static str,
    /// What it is, in one line (frames and signs of `docs/conventions.md`).
    pub meaning: &'static str,
}

impl Quantity {
    /// The column names of this quantity: its name, or the three names of a per-beam one.
    pub fn columns(&self) -> Vec<String> {
        if self.name.contains("{i}") {
            (1..=3).map(|i| self.name.replace("{i}", &i.to_string())).collect()
        } else {
            vec![self.name.to_string()]
        }
    }
}

const fn q(name: &'static str, unit: &'static str, meaning: &'static str) -> Quantity {
    Quantity { name, unit, meaning }
}

/// Every column of every CSV flexstar writes for a run or a motion: the solver results (the
/// fixed columns, the AMM's and the FEM's), a direct run's file, `kinematics.csv`, the
/// controller's `setpoints.csv` (`flexstar export`) and a run's `<stem>-dwells.csv`.
pub const QUANTITIES: &[Quantity] = &[
    q("t", "s", "time"),
    // the fixed columns of every solver result
    q(
        "w{i}G",
        "m",
        "elastic displacement of G projected on beam i's normal e_wi",
    ),
    q(
        "w{i}tip",
        "m",
        "elastic deflection of beam i's tip, w_i(L), in its rigid frame (points A, B, C)",
    ),
    q(
        "Fa{i}",
        "N",
        "force actuator i applies to its slider along +u_i (Eq. 33)",
    ),
    // the AMM's multipliers and coordinates
    q("Fix{i}", "N", "axial force on beam i at G (Eq. 38)"),
    q("M{i}G", "N m", "couple on beam i at G (Eq. 39)"),
    q("Fw", "N", "shear force on each beam at G (Eq. 40)"),
    q(
        "Fp{i}",
        "N",
        "normal force of sleeve pin i on beam i, along e_wi (Eq. 41)",
    ),
    q("FLp{i}", "N", "normal force at the left edge of sleeve i (Eq. 42)"),
    q("FRp{i}", "N", "normal force at the right edge of sleeve i (Eq. 42)"),
    q("Mp{i}", "N m", "moment of beam i on sleeve i (Eq. 43)"),
    q(
        "thp{i}",
        "rad",
        "rotation of sleeve i relative to the rigid beam (the beam's slope there)",
    ),
    q("u{i}", "m", "axial displacement of beam i"),
    // the elastic displacement of G, both solvers
    q("dGx", "m", "elastic displacement of G, x, fixed frame"),
    q("dGy", "m", "elastic displacement of G, y, fixed frame"),
    // the FEM's columns
    q(
        "xp{i}",
        "m",
        "where sleeve i sits on beam i, from G (material coordinate; Eq. 10 when rigid)",
    ),
    q(
        "Fn{i}",
        "N",
        "force of sleeve i on beam i along e_wi (the paper's Fp + FL + FR)",
    ),
    q("Ek_star", "J", "kinetic energy of the three beams"),
    q("Ek_sleeves", "J", "kinetic energy of the sleeve rotations"),
    q("Ek_sliders", "J", "kinetic energy of the sliders (mpp + mpa)"),
    q("U", "J", "strain energy (bending and axial)"),
    q("W", "J", "work of the drivers since t = 0"),
    q("slopeG", "rad", "elastic slope of the beams at G"),
    // the energies of the payload, damping and load (FEM), each only with its section
    q("Ek_payload", "J", "kinetic energy of the payload welded at G"),
    q("W_load", "J", "work of the load at G since t = 0"),
    q("E_d", "J", "energy dissipated by the beams' damping since t = 0"),
    q(
        "V_g",
        "J",
        "potential energy of the weights (beams, payload, sleeves, sliders)",
    ),
    // friction (both solvers), only with a [friction] section (docs/friction.md 7, 9)
    q(
        "Ff{i}",
        "N",
        "friction force of sleeve i on beam i along e_xi (stuck: the force the stick needs)",
    ),
    q("vs{i}", "m/s", "sliding speed of sleeve i along beam i (> 0: towards the tip)"),
    q("stick{i}", "-", "1 while sleeve i is stuck on its beam, 0 while it slips"),
    q("E_f", "J", "energy dissipated by the friction of the sleeves and rails since t = 0"),
    // a direct run's columns and kinematics.csv
    q("s{i}", "m", "position of slider i along its axis (Eqs. 1-3)"),
    q("sd{i}", "m/s", "velocity of slider i"),
    q("sdd{i}", "m/s^2", "acceleration of slider i"),
    q("Gx", "m", "rigid junction G, x, fixed frame"),
    q("Gy", "m", "rigid junction G, y, fixed frame"),
    q(
        "theta",
        "rad",
        "orientation of the rigid star (Eq. 9), counter-clockwise",
    ),
    q("e{i}", "m", "servo tracking error of slider i, s_ref,i - s_i"),
    q("aGx", "m/s^2", "acceleration of rigid G, x, fixed frame"),
    q("aGy", "m/s^2", "acceleration of rigid G, y, fixed frame"),
    q("thetadot", "rad/s", "angular velocity of the rigid star"),
    q("thetaddot", "rad/s^2", "angular acceleration of the rigid star"),
    // setpoints.csv (flexstar export): the motion's exact derivatives and the feed-forward
    q(
        "v{i}",
        "m/s",
        "setpoint velocity of slider i, exact derivative of the motion",
    ),
    q("a{i}", "m/s^2", "setpoint acceleration of slider i, exact"),
    q("j{i}", "m/s^3", "setpoint jerk of slider i, exact"),
    q(
        "F{i}",
        "N",
        "feed-forward force of actuator i along +u_i: the accurate AMM's Fa_i at the sample time",
    ),
    // <stem>-dwells.csv: the residual per dwell (docs/motions.md 2.5)
    q("dwell", "-", "number of the dwell (and of the move before it), from 1"),
    q("move_start", "s", "start of the move before the dwell"),
    q("move_end", "s", "end of that move: the sliders come to rest"),
    q("t_start", "s", "start of the dwell (= move_end)"),
    q(
        "t_end",
        "s",
        "end of the dwell: the next move's start, or the run's last output time",
    ),
    q("G_peak_m", "m", "largest |dG| in the dwell"),
    q("G_rms_m", "m", "RMS of |dG| over the dwell (trapezoidal)"),
    q("tip_peak_m", "m", "largest |w_i(L)| of the three tips in the dwell"),
    q(
        "tip_rms_m",
        "m",
        "RMS over the dwell of sqrt(1/3 sum_i w_i(L)^2)",
    ),
    q(
        "settle_s",
        "s",
        "last time in the dwell with |dG| above settle_tol, when the dwell then ends with settle_hold_s in the band; empty when not",
    ),
    q("settled", "-", "settled within the dwell: true or false"),
    q(
        "settle_hold_s",
        "s",
        "one period of the first elastic mode at the dwell's pose, sliders locked",
    ),
    q("note", "-", "why a value is empty or the dwell cannot settle"),
];

/// The declared quantity that column `name` belongs to (`w2G`: `w{i}G`).
pub fn quantity_of(name: &str) -> Option<&'static Quantity> {
    QUANTITIES.iter().find(|q| q.columns().iter().any(|c| c == name))
}

/// The unit of column `name`, `None` for a name flexstar does not write.
pub fn column_unit(name: &str) -> Option<&'static str> {
    quantity_of(name).map(|q| q.unit)
}

/// `{column: unit}` for the columns `names` (the sidecar's `column_units`); a column that is not
/// declared gets `null` (the tests keep every writer's columns declared).
pub fn column_units<S: AsRef<str>>(names: &[S]) -> serde_json::Value {
    let map = names
        .iter()
        .map(|n| {
            let unit = column_unit(n.as_ref()).map_or(serde_json::Value::Null, |u| u.into());
            (n.as_ref().to_string(), unit)
        })
        .collect::<serde_json::Map<_, _>>();
    serde_json::Value::Object(map)
}

/// The column index of `docs/outputs.md` (between its `column index` markers): one row per
/// declared quantity, in declaration order.
pub fn column_index_markdown() -> String {
    let mut out = String::from("| column | unit | meaning |\n|---|---|---|\n");
    for q in QUANTITIES {
        let cols = q.columns();
        let name = match cols.len() {
            1 => format!("`{}`", cols[0]),
            _ => format!("`{}`, `{}`, `{}`", cols[0], cols[1], cols[2]),
        };
        out.push_str(&format!("| {name} | {} | {} |\n", q.unit, q.meaning));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_is_declared_once() {
        let mut names: Vec<String> = QUANTITIES.iter().flat_map(|q| q.columns()).collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "a column declared twice");
        assert_eq!(column_unit("M2G"), Some("N m"));
        assert_eq!(column_unit("sdd3"), Some("m/s^2"));
        assert_eq!(column_unit("w4G"), None);
        assert_eq!(
            column_units(&["t", "nope"]),
            serde_json::json!({"t": "s", "nope": null})
        );
    }

    /// `docs/outputs.md`'s column index is the one generated from [`QUANTITIES`]; to update it
    /// after a change here, run this test with `FLEXSTAR_WRITE_DOCS=1`.
    #[test]
    fn the_column_index_of_the_docs_is_generated_from_the_declarations() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/outputs.md");
        let text = std::fs::read_to_string(path).unwrap();
        let (begin, end) = ("<!-- column index: begin -->\n", "<!-- column index: end -->");
        let a = text.find(begin).expect("the begin marker") + begin.len();
        let b = text.find(end).expect("the end marker");
        let want = column_index_markdown();
        if std::env::var_os("FLEXSTAR_WRITE_DOCS").is_some() {
            std::fs::write(path, format!("{}{want}{}", &text[..a], &text[b..])).unwrap();
            return;
        }
        assert_eq!(
            &text[a..b],
            want,
            "docs/outputs.md's column index differs from QUANTITIES (FLEXSTAR_WRITE_DOCS=1 rewrites it)"
        );
    }
}
