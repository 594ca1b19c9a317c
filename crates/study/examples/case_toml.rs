//! The experiment file of one case of a study, to rerun it alone (`flexstar run`, `flexstar
//! compare`): `cargo run --release -p flexstar-study --example case_toml -- STUDY.toml RUN_ID`
//! writes its TOML to stdout. Paths in it (a table trajectory, a forces file) are relative to the
//! study's base file: write it beside the base. RUN_ID may be a unique prefix of the run id (the
//! 8 characters the docs quote).

use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, study, run_id] = args.as_slice() else {
        eprintln!("usage: case_toml STUDY.toml RUN_ID");
        std::process::exit(2);
    };
    let study = match flexstar_study::Study::load(Path::new(study)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let matching: Vec<_> = study
        .cases()
        .into_iter()
        .filter(|c| c.run_id.starts_with(run_id.as_str()))
        .collect();
    let [case] = matching.as_slice() else {
        eprintln!(
            "{}: {} cases with a run id starting {run_id}",
            study.file.display(),
            matching.len()
        );
        std::process::exit(1);
    };
    match study.case_toml(&case.values) {
        Ok(text) => print!("{text}"),
        Err(e) => {
            eprintln!("{}: case {run_id}: {e}", study.file.display());
            std::process::exit(1);
        }
    }
}
