//! Derived keys of a study (`docs/studies.md`, "Derived keys"): robot parameters given as the
//! dimensionless groups a validation envelope is drawn in (`docs/validation.md` sections 8 and 9,
//! `configs/studies/envelope.toml`, `envelope-as-built.toml`), per-beam deviations of a robot as
//! built, gravity, and a motion scaled to the robot. They are applied after the plain keys, in the
//! order of [`DERIVED`], each reading the values set before it (the paper's value where the
//! document sets none; a key given as three values per beam is read beam by beam, beam k's
//! values for beam k):
//!
//! - `derived.EI` [N m^2]: `robot.I = EI / robot.E`;
//! - `derived.Lp_over_L` [-]: `robot.Lp = v robot.L`;
//! - `derived.Jp_over_rhoL3` [-]: `robot.Jp = v robot.rho robot.L^3`;
//! - `derived.dev.<X>[k]` [-], X one of [`DEV_BEAM_KEYS`]: a factor on beam k's value of X
//!   (`EI` scales `robot.I`): `derived.dev.L[2] = 1.1` makes beam 2 10 % longer than the value
//!   set before; without an index the factor goes to the three beams;
//! - `derived.d_share` [0, 1]: `robot.d` from `max_k (Lp_k/2 + 0.15 L_k)` (v = 0) to
//!   `min_k (L_k - Lp_k/2 - 0.15 L_k)` (v = 1), every sleeve at least 0.15 of its beam's length
//!   from G and from the tip at the start;
//! - `derived.load_share` [-]: the motion's acceleration `a` chosen so that four times the
//!   static deflection of the overhang beyond the sleeve, `l_k = L_k - d`, under its inertial load
//!   `rho_k a`, `4 rho_k a l_k^4 / (8 EI_k)`, is `v` times the small-deflection limit `0.05 L_k` on
//!   the beam that reaches it first (the smallest `a` of the three; the factor 4: the median of
//!   peak tip over the static estimate on the envelope's first draw, which spread from 1 to 14; a
//!   scale, not a prediction: `docs/studies.md`); the motion is then a polynomial (case 3's shape,
//!   `s1 = a/2 t^2`, `s2 = 0`, `s3 = a/4 t^2`) over the time in which slider 1 travels
//!   `0.1 L_min` (the shortest beam's length), or, with `derived.motion = "quintic"`, a
//!   rest-to-rest quintic of G by `0.1 L_min` along x and `-0.05 L_min` along y whose peak
//!   acceleration `5.77 D / T^2` is `a`, with `t_end = 2.5 T` (a residual window after it);
//! - `derived.g_share` [0, 1] and `derived.g_deg` [deg]: gravity `|g| (cos, sin)(g_deg)` in the
//!   plane (`g_deg` from the X axis, counter-clockwise; default 270, straight down; `g_share`
//!   default 1 when only `g_deg` is given), with `|g| = v min(9.81, g_cap)`: `g_cap` is the gravity
//!   along `g_deg` under which the star's static sag at the start (a linear estimate,
//!   [`crate::sag`], Eqs. D1-D4 of `docs/studies.md`) reaches a quarter ([`G_SAG_SHARE`]) of the
//!   nearest small-deflection bound (`|w_iG|`, the tips, the sleeves' slope), so that the sag
//!   stays well inside the range however soft the robot (a quarter of the envelope's robots take
//!   the whole 9.81 m/s^2, the median about 3 m/s^2);
//! - `derived.dev.sides[k]` [-]: a factor on side k of the base, the sides of the base set
//!   before (`base.sides`, or `2 sqrt(3) d` of `robot.d`, which it then removes).

use crate::key::{self, Key};

/// The derived keys (without an index), in the order they are applied.
pub const DERIVED: [&str; 15] = [
    "derived.EI",
    "derived.Lp_over_L",
    "derived.Jp_over_rhoL3",
    "derived.dev.L",
    "derived.dev.EI",
    "derived.dev.rho",
    "derived.dev.Lp",
    "derived.dev.Jp",
    "derived.dev.mpp_mpa",
    "derived.d_share",
    "derived.motion",
    "derived.load_share",
    "derived.g_share",
    "derived.g_deg",
    "derived.dev.sides",
];

/// The beam keys a per-beam deviation `derived.dev.<X>[k]` scales (`EI` scales `robot.I`).
pub const DEV_BEAM_KEYS: [&str; 6] = ["L", "EI", "rho", "Lp", "Jp", "mpp_mpa"];

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
/// The largest gravity of `derived.g_share` [m/s^2].
pub const G_EARTH: f64 = 9.81;
/// The share of the nearest small-deflection bound that the star's static sag may reach under
/// `derived.g_share = 1` (module docs).
pub const G_SAG_SHARE: f64 = 0.25;
/// The default direction of gravity [deg]: straight down (-Y).
const G_DEG_DEFAULT: f64 = 270.0;

/// Is `key` a derived key (`derived.dev.*` with or without an index)?
pub fn is_derived(key: &str) -> bool {
    Key::parse(key).is_ok_and(|k| DERIVED.contains(&k.path.as_str()))
}

fn float(v: f64) -> toml::Value {
    toml::Value::Float(crate::sample::tidy(v))
}

/// The three beams' values of `robot.<name>` in `doc` (the paper's where it sets none).
fn beams(doc: &toml::Table, name: &str) -> Result<[f64; 3], String> {
    let v = key::numbers_at(doc, &format!("robot.{name}"))?;
    Ok([v[0], v[1], v[2]])
}

/// Set `robot.<name>` to the three beams' values `v`: one number when they agree bit for bit.
fn set_beams(doc: &mut toml::Table, name: &str, v: [f64; 3]) -> Result<(), String> {
    let value = if v[0].to_bits() == v[1].to_bits() && v[1].to_bits() == v[2].to_bits() {
        float(v[0])
    } else {
        toml::Value::Array(v.into_iter().map(float).collect())
    };
    key::set(doc, &Key::parse(&format!("robot.{name}"))?, value)
}

fn min3(v: [f64; 3]) -> f64 {
    v[0].min(v[1]).min(v[2])
}

fn max3(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

/// The derived values of one case, by key.
struct Values<'a>(Vec<(Key, &'a toml::Value)>);

impl Values<'_> {
    fn get(&self, path: &str) -> Option<&toml::Value> {
        self.0
            .iter()
            .find(|(k, _)| k.path == path && k.index.is_none())
            .map(|(_, v)| *v)
    }

    fn num(&self, path: &str) -> Result<Option<f64>, String> {
        self.get(path)
            .map(|v| crate::patch::number(v).ok_or_else(|| format!("{path} must be a number, got {v}")))
            .transpose()
    }

    /// The factors of `derived.dev.<name>` for the three beams (sides), `None` when none is given.
    fn factors(&self, name: &str) -> Result<Option<[f64; 3]>, String> {
        let path = format!("{}{name}", key::DEV_PREFIX);
        let mut f = [1.0; 3];
        let mut any = false;
        for (k, v) in self.0.iter().filter(|(k, _)| k.path == path) {
            let x = crate::patch::number(v).ok_or_else(|| format!("{} must be a number, got {v}", k.text()))?;
            if !(x.is_finite() && x > 0.0) {
                return Err(format!("{} must be a positive factor, got {x}", k.text()));
            }
            match k.index {
                Some(i) => f[i - 1] = x,
                None => f = [x; 3],
            }
            any = true;
        }
        Ok(any.then_some(f))
    }
}

/// Apply the derived `values` (by key) to `doc`, in the order of [`DERIVED`].
pub fn apply(doc: &mut toml::Table, values: &[(&str, &toml::Value)]) -> Result<(), String> {
    let values = Values(
        values
            .iter()
            .map(|(k, v)| Key::parse(k).map(|k| (k, *v)))
            .collect::<Result<_, _>>()?,
    );
    groups(doc, &values)?;
    deviations(doc, &values)?;
    if let Some(v) = values.num("derived.d_share")? {
        d_share(doc, v)?;
    }
    let quintic = match values.get("derived.motion").map(|v| v.as_str()) {
        None | Some(Some("polynomial")) => false,
        Some(Some("quintic")) => true,
        Some(other) => {
            return Err(format!(
                "derived.motion must be \"polynomial\" or \"quintic\", got {other:?}"
            ))
        }
    };
    if let Some(q) = values.num("derived.load_share")? {
        motion(doc, q, quintic)?;
    }
    gravity(doc, values.num("derived.g_share")?, values.num("derived.g_deg")?)?;
    if let Some(f) = values.factors("sides")? {
        let s = key::numbers_at(doc, "base.sides").map_err(|e| format!("derived.dev.sides: {e}"))?;
        let sides = (0..3).map(|k| float(s[k] * f[k])).collect();
        key::set(doc, &Key::parse("base.sides")?, toml::Value::Array(sides))?;
    }
    Ok(())
}

/// `derived.EI`, `derived.Lp_over_L`, `derived.Jp_over_rhoL3` (module docs).
fn groups(doc: &mut toml::Table, values: &Values) -> Result<(), String> {
    if let Some(ei) = values.num("derived.EI")? {
        let e = beams(doc, "E")?;
        set_beams(doc, "I", e.map(|e| ei / e))?;
    }
    if let Some(r) = values.num("derived.Lp_over_L")? {
        let l = beams(doc, "L")?;
        set_beams(doc, "Lp", l.map(|l| r * l))?;
    }
    if let Some(r) = values.num("derived.Jp_over_rhoL3")? {
        let (rho, l) = (beams(doc, "rho")?, beams(doc, "L")?);
        set_beams(doc, "Jp", std::array::from_fn(|k| r * rho[k] * l[k].powi(3)))?;
    }
    Ok(())
}

/// `derived.dev.<X>[k]`: beam k's value of X times the factor (module docs).
fn deviations(doc: &mut toml::Table, values: &Values) -> Result<(), String> {
    for name in DEV_BEAM_KEYS {
        let Some(f) = values.factors(name)? else {
            continue;
        };
        let target = if name == "EI" { "I" } else { name };
        let v = beams(doc, target)?;
        set_beams(doc, target, std::array::from_fn(|k| v[k] * f[k]))?;
    }
    Ok(())
}

/// `derived.d_share = v` (module docs).
fn d_share(doc: &mut toml::Table, v: f64) -> Result<(), String> {
    if crate::patch::get_dotted(doc, "base.sides").is_some() {
        return Err(
            "derived.d_share sets robot.d, but the base gives base.sides: vary derived.dev.sides instead".into(),
        );
    }
    let (l, lp) = (beams(doc, "L")?, beams(doc, "Lp")?);
    let lo = max3(std::array::from_fn(|k| lp[k] / 2.0 + D_MARGIN * l[k]));
    let hi = min3(std::array::from_fn(|k| l[k] - lp[k] / 2.0 - D_MARGIN * l[k]));
    crate::patch::set_dotted(doc, "robot.d", float(lo + v * (hi - lo)))
}

/// The overhangs beyond the sleeves at the start, `l_k = L_k - d`, and the beams' `EI_k`, `rho_k`,
/// `L_k`.
struct Overhangs {
    l: [f64; 3],
    overhang: [f64; 3],
    ei: [f64; 3],
    rho: [f64; 3],
}

fn overhangs(doc: &toml::Table) -> Result<Overhangs, String> {
    let (l, rho, e, i) = (beams(doc, "L")?, beams(doc, "rho")?, beams(doc, "E")?, beams(doc, "I")?);
    let d = key::in_radius(doc);
    Ok(Overhangs {
        l,
        overhang: l.map(|l| l - d),
        ei: std::array::from_fn(|k| e[k] * i[k]),
        rho,
    })
}

/// The motion of `derived.load_share = q` (module docs).
fn motion(doc: &mut toml::Table, q: f64, quintic: bool) -> Result<(), String> {
    let o = overhangs(doc)?;
    let a = min3(std::array::from_fn(|k| {
        q * DEFLECTION_LIMIT * o.l[k] * 8.0 * o.ei[k] / (DYNAMIC * o.rho[k] * o.overhang[k].powi(4))
    }));
    if !(a.is_finite() && a > 0.0) {
        return Err(format!("derived.load_share: no positive acceleration from q = {q}"));
    }
    let l = min3(o.l);
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
    crate::patch::set_dotted(doc, "time.t_end", float(t_end))
}

/// Gravity of `derived.g_share` and `derived.g_deg` (module docs); nothing when neither is given.
fn gravity(doc: &mut toml::Table, share: Option<f64>, deg: Option<f64>) -> Result<(), String> {
    let share = match (share, deg) {
        (None, None) => return Ok(()),
        (Some(v), _) => v,
        (None, Some(_)) => 1.0,
    };
    if !(share.is_finite() && share >= 0.0) {
        return Err(format!("derived.g_share must be a share >= 0, got {share}"));
    }
    let angle = deg.unwrap_or(G_DEG_DEFAULT).to_radians();
    let unit = [angle.cos(), angle.sin()];
    let cap = G_SAG_SHARE / sag_share(doc, unit)?;
    if !(cap.is_finite() && cap > 0.0) {
        return Err(format!(
            "derived.g_share: no positive gravity for this robot (cap {cap})"
        ));
    }
    let g = share * G_EARTH.min(cap);
    let v = toml::Value::Array(vec![float(g * unit[0]), float(g * unit[1])]);
    crate::patch::set_dotted(doc, "gravity.g", v)
}

/// The largest share of a small-deflection bound (`flexstar_metrics::validity`: `|w_iG|` and the
/// tips against 0.05 of the shortest beam, the sleeves' slope against 0.075 rad) that the sag of
/// Eqs. D1-D4 (`crate::sag`) reaches under the unit gravity `unit` [m/s^2] at the start of the
/// motion (the sleeves at `d` from G).
fn sag_share(doc: &toml::Table, unit: [f64; 2]) -> Result<f64, String> {
    use flexstar_metrics::validity::{G_BOUND, SLOPE_BOUND, TIP_BOUND};
    let (l, rho, e, i) = (beams(doc, "L")?, beams(doc, "rho")?, beams(doc, "E")?, beams(doc, "I")?);
    let weld = key::numbers_at(doc, "robot.weld_deg")?;
    let arms: [crate::sag::Arm; 3] = std::array::from_fn(|k| crate::sag::Arm {
        l: l[k],
        ei: e[k] * i[k],
        rho: rho[k],
        weld: weld[k].to_radians(),
    });
    let sag = crate::sag::star_sag(&arms, key::in_radius(doc), unit)
        .ok_or("derived.g_share: the star's statics are singular for this robot")?;
    let l_min = min3(l);
    let largest = |v: [f64; 3]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    Ok((largest(sag.w_g) / (G_BOUND * l_min))
        .max(largest(sag.w_tip) / (TIP_BOUND * l_min))
        .max(largest(sag.slope) / SLOPE_BOUND))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Beam 1's value of `robot.<k>` (`robot.d` as it is).
    fn robot(doc: &toml::Table, k: &str) -> f64 {
        if k == "d" {
            return key::in_radius(doc);
        }
        beams(doc, k).unwrap()[0]
    }

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
        // one number per key: the beams are equal
        assert!(d["robot"]["I"].is_float() && d["robot"]["Jp"].is_float());
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

    /// Per-beam factors scale each beam's value; the sleeve's place and the motion follow the beam
    /// that limits them, each checked by its defining inequality written out here.
    #[test]
    fn deviations_scale_each_beam_and_the_limits_follow_the_weakest() {
        let mut d = doc();
        let vals = [
            ("derived.Lp_over_L", toml::Value::Float(0.1)),
            ("derived.dev.L[2]", toml::Value::Float(0.9)),
            ("derived.dev.EI[3]", toml::Value::Float(0.8)),
            ("derived.dev.rho", toml::Value::Float(1.1)),
            ("derived.d_share", toml::Value::Float(1.0)),
            ("derived.load_share", toml::Value::Float(0.3)),
            ("derived.dev.sides[1]", toml::Value::Float(1.05)),
        ];
        let refs: Vec<(&str, &toml::Value)> = vals.iter().map(|(k, v)| (*k, v)).collect();
        apply(&mut d, &refs).unwrap();
        let (l, lp, i, rho) = (
            beams(&d, "L").unwrap(),
            beams(&d, "Lp").unwrap(),
            beams(&d, "I").unwrap(),
            beams(&d, "rho").unwrap(),
        );
        assert_eq!(l, [0.4, 0.36, 0.4]);
        // Lp from the nominal L, before the deviation of L
        assert_eq!(lp, [0.04; 3]);
        let paper_i = flexstar_model::RobotParams::paper().i;
        assert_eq!(i, [paper_i, paper_i, crate::sample::tidy(paper_i * 0.8)]);
        assert_eq!(rho, [0.11; 3]);
        // d_share = 1 puts every sleeve 0.15 L_k + Lp/2 from its tip at least, beam 2 exactly
        let sides = key::numbers_at(&d, "base.sides").unwrap();
        let dd = sides[1] / (2.0 * 3f64.sqrt());
        assert!((l[1] - dd - (0.15 * l[1] + 0.02)).abs() < 1e-12, "{dd}");
        assert!((0..3).all(|k| l[k] - dd >= 0.15 * l[k] + 0.02 - 1e-12));
        // side 1 is 5 % longer; robot.d is gone with the sides
        assert!((sides[0] / sides[1] - 1.05).abs() < 1e-11 && sides[1] == sides[2]);
        assert!(d["robot"].get("d").is_none());
        // the motion: the largest estimate over the beams is the asked share, the others below
        let k = d["trajectory"]["s1"].as_array().unwrap()[2].as_float().unwrap();
        let share: Vec<f64> = (0..3)
            .map(|b| 4.0 * rho[b] * 2.0 * k * (l[b] - dd).powi(4) / (8.0 * 70e9 * i[b]) / (0.05 * l[b]))
            .collect();
        let top = share.iter().cloned().fold(0.0, f64::max);
        assert!((top - 0.3).abs() < 1e-9, "{share:?}");
    }

    /// Gravity's size is the share of min(9.81, the cap) and its direction the angle: a stiff
    /// robot gets the whole 9.81, a soft one the gravity whose sag (Eqs. D1-D4, `crate::sag`,
    /// checked there by hand statics) reaches a quarter of the nearest bound.
    #[test]
    fn gravity_is_capped_by_the_sag_of_the_star() {
        let share = toml::Value::Float(0.5);
        let deg = toml::Value::Float(30.0);
        let mut stiff = doc();
        crate::patch::set_dotted(&mut stiff, "robot.I", toml::Value::Float(2.5e-11)).unwrap();
        apply(&mut stiff, &[("derived.g_share", &share), ("derived.g_deg", &deg)]).unwrap();
        let g = key::numbers_at(&stiff, "gravity.g").unwrap();
        assert!((g[0].hypot(g[1]) - 0.5 * 9.81).abs() < 1e-9 && (g[1].atan2(g[0]).to_degrees() - 30.0).abs() < 1e-9);
        let mut soft = doc();
        crate::patch::set_dotted(&mut soft, "robot.I", toml::Value::Float(2.5e-13)).unwrap();
        let one = toml::Value::Float(1.0);
        apply(&mut soft, &[("derived.g_share", &one)]).unwrap();
        let g = key::numbers_at(&soft, "gravity.g").unwrap();
        assert!(
            g[0].abs() < 1e-12 && g[1] < 0.0 && -g[1] < 9.81,
            "straight down, capped: {g:?}"
        );
        let arms: [crate::sag::Arm; 3] = std::array::from_fn(|k| crate::sag::Arm {
            l: 0.4,
            ei: 70e9 * 2.5e-13,
            rho: 0.1,
            weld: (120.0 * k as f64).to_radians(),
        });
        let s = crate::sag::star_sag(&arms, flexstar_model::RobotParams::paper().d, [g[0], g[1]]).unwrap();
        let big = |v: [f64; 3]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let share = (big(s.w_g) / 0.02).max(big(s.w_tip) / 0.02).max(big(s.slope) / 0.075);
        assert!((share - 0.25).abs() < 1e-9, "{share}");
        // the direction alone: the whole of min(9.81, cap)
        let mut d = stiff.clone();
        d.remove("gravity");
        apply(&mut d, &[("derived.g_deg", &deg)]).unwrap();
        let g = key::numbers_at(&d, "gravity.g").unwrap();
        assert!((g[0].hypot(g[1]) - 9.81).abs() < 1e-9, "{g:?}");
    }
}
