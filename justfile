# flexstar recipes (https://github.com/casey/just); each is one cargo command.

# Reproduce the paper's Table I and figures and check the thresholds (the main job).
verify out="out/verify":
    cargo run --release --bin flexstar -- verify --out {{out}}

# AMM against FEM on your experiment: figures, EVPs and a report in out/<name>/.
compare config *flags:
    cargo run --release --bin flexstar -- compare {{config}} {{flags}}

# Install the flexstar binary (release build in ./target, shared with `just test`).
install:
    cargo install --locked --path crates/cli

# The whole test suite (what CI runs: the README's test command, release profile).
test:
    cargo test --workspace --release

# Criterion benchmarks of the solvers (the `bench` feature of flexstar-amm, -fem and -modal: criterion is compiled only for them).
bench:
    cargo bench --workspace --features bench

# Rigid kinematics of the four paper cases.
kinematics:
    for c in configs/case1.toml configs/case2.toml configs/case3.toml configs/case4.toml; do cargo run --release --bin flexstar -- kinematics $c; done

# Formatting and lints.
lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets
