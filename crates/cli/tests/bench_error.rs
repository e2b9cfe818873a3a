//! `cirrus bench error` on a tiny scene: every configuration is measured at
//! every budget, the files are written, and the report's arithmetic holds
//! (the baseline against itself is exactly 1x; the ceiling is stated).

use std::process::Command;

#[test]
fn error_bench_measures_every_configuration_and_reports_the_ceiling() {
    let out_dir = std::env::temp_dir().join(format!("cirrus_bench_error_{}", std::process::id()));
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/sphere_fog.vdb");
    let out = Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args([
            "bench",
            "error",
            data,
            "--res",
            "12x12",
            "--budgets",
            "0.02,0.04",
        ])
        .args(["--reference-time", "0.3", "--steps", "1", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");

    // 9 tracking configurations (3 estimators x 3 structures), the default
    // one with the automatic structure, random numbers, adaptive, sunward
    // scattering, every light per vertex and (where the library loads)
    // denoised, and 2 ray marchers at one step, each at 2 budgets.
    let denoised = !stderr.contains("not measuring denoising");
    let configs = 9 + 5 + usize::from(denoised) + 2;
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2 * configs, "{csv}");
    for name in [
        "\"automatic structure: ",
        "\"random numbers: ",
        "\"adaptive 2%: ",
        "\"sunward scattering: ",
        "\"every light per vertex: ",
    ] {
        assert_eq!(
            rows.iter().filter(|r| r.starts_with(name)).count(),
            2,
            "{csv}"
        );
    }
    assert_eq!(
        rows.iter().filter(|r| r.starts_with("\"OIDN: ")).count(),
        2 * usize::from(denoised),
        "{csv}"
    );
    for row in &rows {
        let rmse: f64 = row.split(',').nth(4).unwrap().parse().unwrap();
        assert!(rmse.is_finite() && rmse >= 0.0, "{row}");
    }
    assert!(out_dir.join("error_vs_time.png").metadata().unwrap().len() > 1000);
    assert!(out_dir.join("reference.exr").exists());

    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    let baseline = report
        .lines()
        .find(|l| l.starts_with("| delta + ratio, global |"))
        .unwrap_or_else(|| panic!("{report}"));
    assert!(baseline.trim_end().ends_with("| 1.00x |"), "{baseline}");
    assert!(report.contains("## The ceiling on this scene"), "{report}");
    // The point bound lies within the range the run's own timings span
    // (the collision's best timing, the last budget's paths).
    let ceiling = &report[report.find("## The ceiling").unwrap()..];
    let word_after = |line: &str, key: &str| -> Option<String> {
        let i = line.find(key)? + key.len();
        Some(line[i..].split([' ', ':']).next()?.to_string())
    };
    let x = |v: &str| v.trim_end_matches('x').parse::<f64>().ok();
    if let Some(point) = word_after(ceiling, "would be at most ").and_then(|v| x(&v)) {
        let range = ceiling.lines().find(|l| l.contains(" spans "));
        let range = range.unwrap_or_else(|| panic!("{ceiling}"));
        let low = word_after(range, " spans ").and_then(|v| x(&v));
        let low = low.unwrap_or_else(|| panic!("{range}"));
        let high = word_after(range, "x to ").unwrap_or_default();
        assert!(low <= point + 1e-2, "{low} > {point}: {range}");
        if high != "unbounded" {
            let high = x(&high).unwrap_or_else(|| panic!("{high}: {range}"));
            assert!(point <= high + 1e-2, "{point} > {high}: {range}");
        }
    }
    let _ = std::fs::remove_dir_all(&out_dir);
}

#[test]
fn error_bench_measures_only_what_it_is_asked_and_the_baseline() {
    let out_dir = std::env::temp_dir().join(format!("cirrus_bench_only_{}", std::process::id()));
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/sphere_fog.vdb");
    let out = Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args(["bench", "error", data, "--res", "8x8", "--budgets", "0.02"])
        .args([
            "--reference-time",
            "0.2",
            "--steps",
            "1",
            "--only",
            "random",
            "--only",
            "track-length",
        ])
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    // Names are quoted: they hold commas.
    let mut names: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|r| r.split('"').nth(1).unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "delta + ratio, global",
            "delta + track-length, fixed grid",
            "delta + track-length, global",
            "delta + track-length, hierarchy",
            "random numbers: delta + residual, hierarchy"
        ],
        "{csv}"
    );
    let _ = std::fs::remove_dir_all(&out_dir);
}
