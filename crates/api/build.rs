//! Records the git commit the binary is built from (`FLEXSTAR_GIT_COMMIT`, read with
//! `option_env!`); without git or outside a repository the variable stays unset and outputs say
//! "commit unknown".

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
}

fn main() {
    if let Some(commit) = git(&["rev-parse", "--short=12", "HEAD"]) {
        println!("cargo:rustc-env=FLEXSTAR_GIT_COMMIT={commit}");
    }
    // rebuild when HEAD moves (a commit, a checkout); the reflog of HEAD changes on both
    if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
        for f in ["HEAD", "logs/HEAD"] {
            println!("cargo:rerun-if-changed={dir}/{f}");
        }
    } else {
        println!("cargo:rerun-if-changed=build.rs");
    }
}
