//! CI regression: the same checks as `flexstar verify` (configs/thresholds.toml: verdicts, most
//! accurate family per case, EVP bands), so a change that moves an EVP out of its band or flips a
//! verdict fails the test suite. Figures are skipped; the numbers are the same.

use std::path::Path;

use flexstar_compare::verify::{paper_configs, run_verify, VerifyOptions};

#[test]
fn table_one_verdicts_and_evp_bands_hold() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = tempfile::tempdir().unwrap();
    let opts = VerifyOptions {
        configs: paper_configs(&root),
        thresholds: root.join("configs/thresholds.toml"),
        out: out.path().to_path_buf(),
        figures: false,
        n_study: false,
    };
    let outcome = run_verify(&opts).expect("verify runs");
    eprintln!("{}", outcome.table.to_markdown());
    assert!(
        outcome.failures.is_empty(),
        "failed checks:\n{}",
        outcome.failures.join("\n")
    );
    for f in [
        "table1.md",
        "table1.csv",
        "table1.json",
        "case1/fem.csv",
        "case3/amm-free-free.csv",
    ] {
        assert!(out.path().join(f).exists(), "{f} missing");
    }
}
