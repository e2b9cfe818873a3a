//! Phase functions chosen by name, per volume and by override.

use cirrus_scene::{ErrorKind, Overrides, Scene, SceneDescription};

const CLOUD: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cloud.vdb");

fn render(o: Overrides) -> Result<Vec<[f32; 4]>, cirrus_scene::Error> {
    let mut scene = Scene::load(CLOUD.as_ref()).unwrap();
    scene.apply(&Overrides {
        res: Some((24, 16)),
        spp: Some(2),
        ..o
    });
    Ok(scene.render()?.image.rgba)
}

#[test]
fn hg_by_name_is_the_default_bit_for_bit_and_other_phases_differ() {
    let default = render(Overrides::default()).unwrap();
    let hg = render(Overrides {
        phase: Some("hg".into()),
        ..Default::default()
    })
    .unwrap();
    assert_eq!(default, hg);
    for name in ["hg2", "draine", "mie", "rayleigh"] {
        let other = render(Overrides {
            phase: Some(name.into()),
            ..Default::default()
        })
        .unwrap();
        assert_ne!(default, other, "{name}");
        assert!(other.iter().flatten().all(|v| v.is_finite()), "{name}");
    }
}

#[test]
fn bad_phases_are_input_errors_naming_what_is_wrong() {
    let e = render(Overrides {
        phase: Some("mei".into()),
        ..Default::default()
    })
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input);
    assert!(
        e.to_string().contains("mei") && e.to_string().contains("rayleigh"),
        "{e}"
    );
    let e = render(Overrides {
        phase: Some("mie".into()),
        droplet_diameter: Some(0.5),
        ..Default::default()
    })
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input, "{e}");
    let e = render(Overrides {
        phase: Some("table:/no/such/table.txt".into()),
        ..Default::default()
    })
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::File);
    assert!(e.to_string().contains("/no/such/table.txt"), "{e}");
}

#[test]
fn a_scene_files_phase_table_is_relative_to_the_file() {
    let dir = std::env::temp_dir().join(format!("cirrus-phase-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Isotropic: a constant table.
    std::fs::write(dir.join("iso.txt"), "# cos value\n-1 1\n1 1\n").unwrap();
    let text = format!(
        "[render]\nspp = 2\n[camera]\nres = \"24x16\"\n[[volume]]\nfile = \"{CLOUD}\"\nphase = \"table:iso.txt\"\n"
    );
    std::fs::write(dir.join("s.toml"), &text).unwrap();
    let from_table = Scene::load(&dir.join("s.toml")).unwrap().render().unwrap();
    // The same scene with an isotropic HG lobe: the same density, so
    // images agree within noise but not bit for bit.
    let d = SceneDescription::parse(&text.replace("phase = \"table:iso.txt\"", "g = 0")).unwrap();
    let iso = Scene::from_description(d, &dir).unwrap().render().unwrap();
    let mean = |v: &[[f32; 4]]| v.iter().map(|p| p[1] as f64).sum::<f64>() / v.len() as f64;
    let (a, b) = (mean(&from_table.image.rgba), mean(&iso.image.rgba));
    assert!((a - b).abs() < 0.1 * b.max(1e-3), "{a} vs {b}");
    std::fs::remove_dir_all(&dir).ok();
}
