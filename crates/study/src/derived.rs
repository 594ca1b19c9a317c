//! Derived keys of a study (`docs/studies.md`, "Derived keys"): robot parameters given as the
//! dimensionless groups a validation envelope is drawn in (`docs/validation.md` section 8,
//! `configs/studies/envelope.toml`), and a motion scaled to the robot. They are applied after the
//! plain keys, in the order of [`DERIVED`], each reading the values set before it.
//!
//! - `derived.EI` [N m^2]: `robot.I = EI / robot.E`;
//! - `derived.Lp_over_L` [-]: `robot.Lp = v robot.L`;
//! - `derived.Jp_over_rhoL3` [-]: `robot.Jp = v robot.rho robot.L^3`;
//! - `derived.d_share` [0, 1]: `robot.d` from `Lp/2 + 0.15 L` (v = 0) to `L - Lp/2 - 0.15 L`
//!   (v = 1), the sleeve at least 0.15 L from G and from the tip at the start;
//! - `derived.load_share` [-]: the motion's acceleration `a` chosen so that four times the
//!   static deflection of the overhang beyond the sleeve, `l = L - d`, under its inertial load
//!   `rho a`, `4 rho a l^4 / (8 EI)`, is `v` times the small-deflection limit `0.05 L` (the factor
//!   4: the median of peak tip over the static estimate on the envelope's first draw, which
//!   spread from 1 to 14; a scale, not a prediction: `docs/studies.md`); the motion is then
//!   a polynomial (case 3's shape, `s1 = a/2 t^2`, `s2 = 0`, `s3 = a/4 t^2`) over the time in
//!   which slider 1 travels `0.1 L`, or, with `derived.motion = "quintic"`, a rest-to-rest
//!   quintic of G by `0.1 L` along x and `-0.05 L` along y whose peak acceleration
//!   `5.77 D / T^2` is `a`, with `t_end = 2.5 T` (a residual window after it).

/// The derived keys, in the order they are applied.
pub const DERIVED: [&str; 6] = [
    "derived.EI",
    "derived.Lp_over_L",
    "derived.Jp_over_rhoL3",
    "derived.d_share",
    "derived.motion",
    "derived.load_share",
];

/// The sleeve's distance kept from G and from the tip at the start, as a share of L.
const D_MARGIN: f64 = 0.15;
/// The small-deflection limit of the AMM: tip deflection 5 % of L.
const DEFLECTION_LIMIT: f64 = 0.05;
/// Slider travel of the polynomial motion, and G's travel of the quintic, as a share of L.
const TRAVEL: f64 = 0.1;
/// The deflection estimate's factor over the static overhang (module docs).
const DYNAMIC: f64 = 4.0;
/// Peak acceleration of the quintic blend: `max |b''| = 10 / sqrt(3)` for a unit move in unit time.
const QUINTIC_PEAK: f64 = 5.773_502_691_896_258;

/// Is `key` a derived key?
pub fn is_derived(key: &str) -> bool {
    DERIVED.contains(&key)
}

fn robot_value(doc: &toml::Table, key: &str, default: f64) -> f64 {
    doc.get("robot")
        .and_then(|r| r.as_table())
        .and_then(|r| r.get(key))
        .and_then(crate::patch::number)
        .unwrap_or(default)
}

/// The robot value of `key`, the paper's when the document does not set it.
fn robot(doc: &toml::Table, key: &str) -> f64 {
    let paper = flexstar_model::RobotParams::default();
    let default = match key {
        "E" => paper.e,
        "I" => paper.i,
        "rho" => paper.rho,
        "L" => paper.l,
        "d" => paper.d,
        "Lp" => paper.lp,
        _ => f64::NAN,
    };
    robot_value(doc, key, default)
}

fn set(doc: &mut toml::Table, key: &str, v: toml::Value) -> Result<(), String> {
    crate::patch::set_dotted(doc, key, v)
}

fn float(v: f64) -> toml::Value {
    toml::Value::Float(crate::sample::tidy(v))
}

/// Apply the derived `values` (by key) to `doc`, in the order of [`DERIVED`].
pub fn apply(doc: &mut toml::Table, values: &[(&str, &toml::Value)]) -> Result<(), String> {
    let get = |key: &str| values.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
    let num = |key: &str| -> Result<Option<f64>, String> {
        get(key)
            .map(|v| crate::patch::number(v).ok_or_else(|| format!("{key} must be a number, got {v}")))
            .transpose()
    };
    if let Some(ei) = num("derived.EI")? {
        let e = robot(doc, "E");
        set(doc, "robot.I", float(ei / e))?;
    }
    if let Some(r) = num("derived.Lp_over_L")? {
        let l = robot(doc, "L");
        set(doc, "robot.Lp", float(r * l))?;
    }
    if let Some(r) = num("derived.Jp_over_rhoL3")? {
        let (rho, l) = (robot(doc, "rho"), robot(doc, "L"));
        set(doc, "robot.Jp", float(r * rho * l.powi(3)))?;
    }
    if let Some(v) = num("derived.d_share")? {
        let (l, lp) = (robot(doc, "L"), robot(doc, "Lp"));
        let lo = lp / 2.0 + D_MARGIN * l;
        let hi = l - lp / 2.0 - D_MARGIN * l;
        set(doc, "robot.d", float(lo + v * (hi - lo)))?;
    }
    let quintic = match get("derived.motion").map(|v| v.as_str()) {
        None | Some(Some("polynomial")) => false,
        Some(Some("quintic")) => true,
        Some(other) => {
            return Err(format!(
                "derived.motion must be \"polynomial\" or \"quintic\", got {other:?}"
            ))
        }
    };
    if let Some(q) = num("derived.load_share")? {
        motion(doc, q, quintic)?;
    }
    Ok(())
}

/// The motion of `derived.load_share = q` (module docs).
fn motion(doc: &mut toml::Table, q: f64, quintic: bool) -> Result<(), String> {
    let (l, d, rho) = (robot(doc, "L"), robot(doc, "d"), robot(doc, "rho"));
    let ei = robot(doc, "E") * robot(doc, "I");
    let overhang = l - d;
    let a = q * DEFLECTION_LIMIT * l * 8.0 * ei / (DYNAMIC * rho * overhang.powi(4));
    if !(a.is_finite() && a > 0.0) {
        return Err(format!("derived.load_share: no positive acceleration from q = {q}"));
    }
    let mut traj = toml::Table::new();
    let t_end = if quintic {
        let (dx, dy) = (TRAVEL * l, -0.5 * TRAVEL * l);
        let t = (QUINTIC_PEAK * dx.hypot(dy) / a).sqrt();
        let pose = |x: f64, y: f64| {
            toml::Value::Table(toml::Table::from_iter([
                ("Gx".to_string(), float(x)),
                ("Gy".to_string(), float(y)),
                ("theta".to_string(), toml::Value::Float(0.0)),
            ]))
        };
        traj.insert("kind".into(), toml::Value::String("quintic".into()));
        traj.insert("from".into(), pose(0.0, 0.0));
        traj.insert("to".into(), pose(dx, dy));
        traj.insert("t0".into(), toml::Value::Float(0.0));
        traj.insert("t1".into(), float(t));
        2.5 * t
    } else {
        let k = a / 2.0;
        let coef = |c: f64| toml::Value::Array(vec![0.0, 0.0, c].into_iter().map(float).collect());
        traj.insert("kind".into(), toml::Value::String("polynomial".into()));
        traj.insert("s1".into(), coef(k));
        traj.insert("s2".into(), toml::Value::Array(vec![toml::Value::Float(0.0)]));
        traj.insert("s3".into(), coef(k / 2.0));
        (TRAVEL * l / k).sqrt()
    };
    doc.insert("trajectory".into(), toml::Value::Table(traj));
    set(doc, "time.t_end", float(t_end))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> toml::Table {
        toml::from_str("name = \"x\"\n[robot]\nL = 0.4\nrho = 0.1\nE = 70e9\n[time]\nt_end = 0.5\ndt_out = 0.001\n")
            .unwrap()
    }

    /// Each group gives back its own value: Lp / L, Jp / (rho L^3), E I, and the load share from
    /// the cantilever formula it was built with (a textbook static deflection, rho a l^4 / 8 EI,
    /// times the factor 4).
    #[test]
    fn groups_are_recovered_from_the_parameters_they_set() {
        let mut d = doc();
        let vals = [
            ("derived.EI", toml::Value::Float(0.5)),
            ("derived.Lp_over_L", toml::Value::Float(0.1)),
            ("derived.Jp_over_rhoL3", toml::Value::Float(0.02)),
            ("derived.d_share", toml::Value::Float(0.5)),
            ("derived.load_share", toml::Value::Float(0.3)),
        ];
        let refs: Vec<(&str, &toml::Value)> = vals.iter().map(|(k, v)| (*k, v)).collect();
        apply(&mut d, &refs).unwrap();
        let r = |k: &str| robot(&d, k);
        assert!((r("E") * r("I") - 0.5).abs() < 1e-12);
        assert!((r("Lp") / r("L") - 0.1).abs() < 1e-12);
        assert!((r("Jp") / (r("rho") * r("L").powi(3)) - 0.02).abs() < 1e-12);
        // d_share = 0.5: midway between Lp/2 + 0.15 L and L - Lp/2 - 0.15 L, i.e. L / 2
        assert!((r("d") - 0.2).abs() < 1e-12);
        let traj = d["trajectory"].as_table().unwrap();
        let k = traj["s1"].as_array().unwrap()[2].as_float().unwrap();
        let overhang = r("L") - r("d");
        let deflection = 4.0 * r("rho") * 2.0 * k * overhang.powi(4) / (8.0 * 0.5);
        assert!((deflection / (0.05 * r("L")) - 0.3).abs() < 1e-9, "{deflection}");
        // slider 1 travels 0.1 L by t_end
        let t_end = d["time"]["t_end"].as_float().unwrap();
        assert!((k * t_end * t_end - 0.04).abs() < 1e-9);
    }

    /// The quintic's peak acceleration is the one asked (the blend's peak 10 / sqrt 3 D / T^2).
    #[test]
    fn the_quintic_has_the_asked_peak_acceleration() {
        let mut d = doc();
        let q = toml::Value::Float(0.2);
        let m = toml::Value::String("quintic".into());
        apply(&mut d, &[("derived.motion", &m), ("derived.load_share", &q)]).unwrap();
        let traj = d["trajectory"].as_table().unwrap();
        let t1 = traj["t1"].as_float().unwrap();
        let dist = traj["to"]["Gx"]
            .as_float()
            .unwrap()
            .hypot(traj["to"]["Gy"].as_float().unwrap());
        let a = 10.0 / 3f64.sqrt() * dist / (t1 * t1);
        let paper = flexstar_model::RobotParams::default();
        let overhang = 0.4 - paper.d;
        let expected = 0.2 * 0.05 * 0.4 * 8.0 * 70e9 * paper.i / (4.0 * 0.1 * overhang.powi(4));
        assert!((a / expected - 1.0).abs() < 1e-9, "{a} vs {expected}");
    }
}
