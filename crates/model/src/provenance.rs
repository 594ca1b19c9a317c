//! What produced a result file: flexstar's version, the commit it was built from and the date.

use serde::Serialize;

/// What produced a result: flexstar's version, the commit it was built from (when known) and
/// the date of the run (UTC, ISO 8601).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Provenance {
    pub version: String,
    pub commit: Option<String>,
    pub date: String,
}

impl Provenance {
    /// This build's version, the given commit, and now.
    pub fn now(commit: Option<&str>) -> Self {
        let secs = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        Provenance {
            version: env!("CARGO_PKG_VERSION").to_string(),
            commit: commit.filter(|c| !c.is_empty()).map(str::to_string),
            date: utc_date_time(secs),
        }
    }

    /// The first fields of every sidecar: `flexstar_version`, `commit` (`null` when unknown) and
    /// `date`.
    pub fn fields(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut doc = serde_json::Map::new();
        doc.insert("flexstar_version".into(), self.version.clone().into());
        let commit = self.commit.clone().map(Into::into).unwrap_or(serde_json::Value::Null);
        doc.insert("commit".into(), commit);
        doc.insert("date".into(), self.date.clone().into());
        doc
    }
}

/// `YYYY-MM-DDTHH:MM:SSZ` for seconds since 1970-01-01 UTC (proleptic Gregorian calendar; days to
/// civil date after H. Hinnant, "chrono-Compatible Low-Level Date Algorithms").
pub fn utc_date_time(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_of_known_instants() {
        // reference instants: `date -u -d @SECS` (GNU coreutils)
        assert_eq!(utc_date_time(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_date_time(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_date_time(1_700_000_000), "2023-11-14T22:13:20Z");
        assert_eq!(utc_date_time(4_107_542_399), "2100-02-28T23:59:59Z");
    }
}
