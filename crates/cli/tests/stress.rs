//! The numerical stress suite (`cirrus bench stress`) must pass whole:
//! finite pixels, no collision cap hit, analytic answers within bound.

use std::process::Command;

#[test]
fn every_stress_case_is_finite_bounded_and_right() {
    let out = Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args(["bench", "stress", "--json"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let cases: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
    let cases = cases.as_array().unwrap();
    assert!(cases.len() >= 20, "{} cases", cases.len());
    let failed: Vec<&serde_json::Value> = cases.iter().filter(|c| c["passed"] != true).collect();
    assert!(failed.is_empty(), "failed: {failed:#?}");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The bad-voxel case really had bad voxels, and they were counted.
    let bad = cases
        .iter()
        .find(|c| c["name"].as_str().unwrap().starts_with("NaN"))
        .unwrap();
    assert!(bad["sanitized_voxels"].as_u64().unwrap() > 100);
    // Cases with a closed-form answer were checked against it.
    assert!(cases.iter().filter(|c| !c["analytic"].is_null()).count() >= 12);
}
