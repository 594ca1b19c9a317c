//! Patching the base experiment's TOML document at dotted keys: every key the experiment format
//! accepts can be varied, and the experiment loader itself rejects the ones it does not know.
//!
//! Derived keys exist besides the experiment's own: [`SCALE_DURATION`] and the robot groups and
//! scaled motion of [`crate::derived`].

/// `scale.duration = k`: play the motion k times slower (k > 1) or faster (k < 1).
///
/// - quintic trajectory: `t0`, `t1` become `k t0`, `k t1`, and `time.t_end` grows by
///   `(k - 1) t1`, so the time at rest after the motion is kept;
/// - polynomial trajectory: `s_i(t)` becomes `s_i(t / k)` (coefficient of `t^m` divided by
///   `k^m`) and `time.t_end` becomes `k t_end`: the same path, k times slower;
/// - via trajectory: every point's `t` becomes `k t`, and `time.t_end` grows by `(k - 1) t_last`
///   (the rest after the motion is kept, as for the quintic);
/// - table trajectory: refused (the file's times cannot be edited by a patch;
///   `docs/motions.md` section 1.5).
pub const SCALE_DURATION: &str = "scale.duration";

/// The base document with `values[j]` set at `keys[j]` (one entry of a list key for an indexed
/// key, [`crate::key`]; derived keys applied last). An error is a structural problem of the key
/// (a path through a value that is not a table, a non-numeric scale, a list of another length).
pub fn case_document(base: &toml::Table, keys: &[String], values: &[toml::Value]) -> Result<toml::Table, String> {
    let mut doc = base.clone();
    let mut scale = None;
    let mut derived = Vec::new();
    for (key, value) in keys.iter().zip(values) {
        if key == SCALE_DURATION {
            scale = Some(number(value).ok_or_else(|| format!("{SCALE_DURATION} must be a number, got {value}"))?);
        } else if crate::derived::is_derived(key) {
            derived.push((key.as_str(), value));
        } else {
            crate::key::set(&mut doc, &crate::key::Key::parse(key)?, value.clone())?;
        }
    }
    crate::derived::apply(&mut doc, &derived)?;
    if let Some(k) = scale {
        scale_duration(&mut doc, k)?;
    }
    Ok(doc)
}

/// Set `value` at the dotted `key`, creating missing tables on the way.
pub fn set_dotted(doc: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, path) = parts.split_last().ok_or("empty key")?;
    let mut table = doc;
    for (i, p) in path.iter().enumerate() {
        let entry = table
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            other => {
                return Err(format!(
                    "`{}` is a {} in the base experiment, not a table",
                    parts[..=i].join("."),
                    other.type_str()
                ))
            }
        };
    }
    table.insert(last.to_string(), value);
    Ok(())
}

/// The value at the dotted `key` of a TOML document, if there is one.
pub fn get_dotted<'a>(doc: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let mut parts = key.split('.');
    let mut value = doc.get(parts.next()?)?;
    for p in parts {
        value = value.as_table()?.get(p)?;
    }
    Some(value)
}

/// A TOML number as f64.
pub fn number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// How a value is written in the results table and hashed into the run id: numbers in Rust's
/// shortest round-trip form, strings bare, anything else in TOML syntax.
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => format!("{f}"),
        toml::Value::Integer(i) => format!("{i}"),
        toml::Value::String(s) => s.clone(),
        toml::Value::Boolean(b) => format!("{b}"),
        other => other.to_string(),
    }
}

fn scale_duration(doc: &mut toml::Table, k: f64) -> Result<(), String> {
    let get = |doc: &toml::Table, table: &str, key: &str| -> Option<f64> {
        doc.get(table)?.as_table()?.get(key).and_then(number)
    };
    let t_end = get(doc, "time", "t_end").ok_or("scale.duration: the base has no number time.t_end")?;
    let kind = doc
        .get("trajectory")
        .and_then(|t| t.get("kind"))
        .and_then(|k| k.as_str())
        .unwrap_or("")
        .to_string();
    match kind.as_str() {
        "quintic" => {
            let t0 = get(doc, "trajectory", "t0").ok_or("scale.duration: the quintic has no number t0")?;
            let t1 = get(doc, "trajectory", "t1").ok_or("scale.duration: the quintic has no number t1")?;
            set_dotted(doc, "trajectory.t0", toml::Value::Float(k * t0))?;
            set_dotted(doc, "trajectory.t1", toml::Value::Float(k * t1))?;
            set_dotted(doc, "time.t_end", toml::Value::Float(t_end + (k - 1.0) * t1))?;
        }
        "via" => scale_via(doc, k, t_end)?,
        "table" => {
            return Err(format!(
                "{SCALE_DURATION} cannot scale a kind = \"table\" trajectory (its times are in the file): \
                 vary the table file instead"
            ))
        }
        "polynomial" => {
            for s in ["s1", "s2", "s3"] {
                let Some(coefs) = doc.get("trajectory").and_then(|t| t.get(s)).and_then(|c| c.as_array()) else {
                    continue;
                };
                let scaled: Vec<toml::Value> = coefs
                    .iter()
                    .enumerate()
                    .map(|(m, c)| match number(c) {
                        Some(c) => toml::Value::Float(c / k.powi(m as i32)),
                        None => c.clone(),
                    })
                    .collect();
                set_dotted(doc, &format!("trajectory.{s}"), toml::Value::Array(scaled))?;
            }
            set_dotted(doc, "time.t_end", toml::Value::Float(k * t_end))?;
        }
        other => return Err(format!("scale.duration: unknown trajectory kind `{other}`")),
    }
    Ok(())
}

/// `scale.duration` of a via trajectory: each point's `t` times k, the rest after the last kept.
fn scale_via(doc: &mut toml::Table, k: f64, t_end: f64) -> Result<(), String> {
    let points = doc
        .get_mut("trajectory")
        .and_then(|t| t.get_mut("points"))
        .and_then(|p| p.as_array_mut())
        .ok_or("scale.duration: the via trajectory has no array trajectory.points")?;
    let mut last = 0.0f64;
    for (j, p) in points.iter_mut().enumerate() {
        let t = p
            .get("t")
            .and_then(number)
            .ok_or_else(|| format!("scale.duration: point {} of trajectory.points has no number t", j + 1))?;
        let table = p.as_table_mut().expect("a point with a key t is a table");
        table.insert("t".into(), toml::Value::Float(k * t));
        last = last.max(t);
    }
    set_dotted(doc, "time.t_end", toml::Value::Float(t_end + (k - 1.0) * last))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duration_scale_of_via_points_keeps_the_rest_and_refuses_tables() {
        let mut doc: toml::Table = "[time]\nt_end = 1.5\n[trajectory]\nkind = \"via\"\npoints = [\
             { t = 0.0, Gx = 0.0, Gy = 0.0, theta = 0.0 }, { t = 0.4, Gx = 0.01, Gy = 0.0, theta = 0.0 }, \
             { t = 1, Gx = 0.0, Gy = 0.0, theta = 0.0 }]\n"
            .parse()
            .unwrap();
        scale_duration(&mut doc, 2.0).unwrap();
        let t: Vec<f64> = doc["trajectory"]["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| number(&p["t"]).unwrap())
            .collect();
        assert_eq!(t, vec![0.0, 0.8, 2.0]);
        // 0.5 s of rest after the motion, before and after
        assert_eq!(number(&doc["time"]["t_end"]), Some(2.5));
        let mut doc: toml::Table = "[time]\nt_end = 1.5\n[trajectory]\nkind = \"table\"\nfile = \"a.csv\"\n"
            .parse()
            .unwrap();
        let err = scale_duration(&mut doc, 2.0).unwrap_err();
        assert!(err.contains("scale.duration") && err.contains("table"), "{err}");
    }

    #[test]
    fn nested_keys_are_created_and_non_tables_refused() {
        let mut doc: toml::Table = "name = \"x\"\n[trajectory]\nfrom = { Gx = 0.0 }\n".parse().unwrap();
        set_dotted(&mut doc, "robot.Lp", toml::Value::Float(0.04)).unwrap();
        set_dotted(&mut doc, "trajectory.from.Gx", toml::Value::Float(0.01)).unwrap();
        assert_eq!(doc["robot"]["Lp"].as_float(), Some(0.04));
        assert_eq!(doc["trajectory"]["from"]["Gx"].as_float(), Some(0.01));
        let err = set_dotted(&mut doc, "name.x", toml::Value::Integer(1)).unwrap_err();
        assert!(err.contains("`name`"), "{err}");
    }

    #[test]
    fn duration_scale_keeps_the_path_of_a_polynomial() {
        // s(t) = 1 + 2 t + 3 t^2 played twice as slowly: s'(2 t) = s(t) at every t
        let mut doc: toml::Table =
            "[time]\nt_end = 0.5\n[trajectory]\nkind = \"polynomial\"\ns1 = [1.0, 2.0, 3.0]\ns2 = [0.0]\ns3 = [0]\n"
                .parse()
                .unwrap();
        scale_duration(&mut doc, 2.0).unwrap();
        let c: Vec<f64> = doc["trajectory"]["s1"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| number(v).unwrap())
            .collect();
        for t in [0.0, 0.1, 0.37] {
            let slow = c[0] + c[1] * (2.0 * t) + c[2] * (2.0 * t) * (2.0 * t);
            assert!((slow - (1.0 + 2.0 * t + 3.0 * t * t)).abs() < 1e-14);
        }
        assert_eq!(number(&doc["time"]["t_end"]), Some(1.0));
    }

    #[test]
    fn duration_scale_keeps_the_rest_after_a_quintic() {
        let mut doc: toml::Table = "[time]\nt_end = 0.5\n[trajectory]\nkind = \"quintic\"\nt0 = 0.1\nt1 = 0.3\n"
            .parse()
            .unwrap();
        scale_duration(&mut doc, 1.5).unwrap();
        let t1 = number(&doc["trajectory"]["t1"]).unwrap();
        let t_end = number(&doc["time"]["t_end"]).unwrap();
        assert!((t1 - 0.45).abs() < 1e-15 && (number(&doc["trajectory"]["t0"]).unwrap() - 0.15).abs() < 1e-15);
        assert!((t_end - t1 - 0.2).abs() < 1e-15, "rest after the motion kept: {t_end}");
    }
}
