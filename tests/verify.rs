//! CI regression: the same checks as `flexstar verify` (configs/thresholds.toml: verdicts, most
//! accurate family per case, EVP bands), so a change that moves an EVP out of its band or flips a
//! verdict fails the test suite. Figures are skipped; the numbers are the same.

use flexstar_compare::verify::{run_verify, VerifyOptions};
use flexstar_model::Provenance;

#[test]
fn table_one_verdicts_and_evp_bands_hold() {
    let out = tempfile::tempdir().unwrap();
    let opts = VerifyOptions {
        configs: None,
        thresholds: None,
        out: out.path().to_path_buf(),
        figures: false,
        n_study: false,
        provenance: Provenance::now(None),
    };
    let outcome = run_verify(&opts, None).expect("verify runs");
    eprintln!("{}", outcome.table.to_markdown());
    assert!(
        outcome.failures.is_empty(),
        "failed checks:\n{}",
        outcome.failures.join("\n")
    );
    // every check is listed with its value and bound, passed ones included
    let checks = std::fs::read_to_string(out.path().join("checks.txt")).unwrap();
    assert_eq!(
        checks.lines().filter(|l| l.starts_with("PASS ")).count(),
        outcome.checks.len()
    );
    assert!(
        checks.contains("mean EVP of free-free") && checks.contains("(required: ["),
        "{checks}"
    );
    for f in [
        "table1.md",
        "table1.csv",
        "table1.json",
        "case1/fem.csv",
        "case1/fem.json",
        "case3/amm-free-free.csv",
        "case3/compare.csv",
        "case3/compare.md",
        "case3/compare.json",
    ] {
        assert!(out.path().join(f).exists(), "{f} missing");
    }
    // the paper's finding in case 2 is explained under Table I
    let md = std::fs::read_to_string(out.path().join("table1.md")).unwrap();
    assert!(md.contains("Note 1 (case2)"), "{md}");
}
