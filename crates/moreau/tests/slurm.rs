//! A sweep on a real SLURM scheduler (opt-in, root, installs slurm-wlm and munge): a 4-task job
//! array and a dependent merge job give tables byte-identical to a local run
//! (`scripts/slurm-check.sh`). `cargo test --release -p moreau --test slurm -- --ignored`.
#[test]
#[ignore]
fn job_array_and_dependent_merge_match_a_local_run() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let out = std::process::Command::new("bash")
        .arg(format!("{root}/scripts/slurm-check.sh"))
        .env("MOREAU", env!("CARGO_BIN_EXE_moreau"))
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && text.contains("byte-identical"), "{text}");
}
