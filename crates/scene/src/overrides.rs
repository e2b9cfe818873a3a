//! [`Overrides`]: every setting with a flag as a plain optional field,
//! declared with the others in `description.rs`; here is what a field-by-
//! field write cannot say.

use crate::description::SceneDescription;
pub use crate::description::{examples, settings, Overrides};

impl Overrides {
    /// `spp` and `time` are one choice: giving either replaces the file's.
    pub(crate) fn apply_exclusive(&self, d: &mut SceneDescription) {
        if self.spp.is_some() || self.time.is_some() {
            d.render.spp = self.spp;
            d.render.time = self.time;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::Colour;

    #[test]
    fn given_fields_win_and_absent_ones_keep_the_file() {
        let mut d = SceneDescription::parse(
            r#"
            [render]
            spp = 8
            seed = 3
            [camera]
            fov = 30
            [sun]
            irradiance = [1, 1, 1]
            [[volume]]
            file = "a.vdb"
            albedo = [0.5, 0.6, 0.7]
            g = 0.2
            [[volume]]
            file = "b.vdb"
            "#,
        )
        .unwrap();
        let o = Overrides {
            time: Some(2.0),
            g: Some(-0.3),
            sun_dir: Some([0.0, -1.0, 0.0]),
            camera_from: Some([1.0; 3]),
            camera_to: Some([0.0; 3]),
            ..Default::default()
        };
        o.apply(&mut d);
        assert_eq!((d.render.spp, d.render.time), (None, Some(2.0)));
        assert_eq!(d.render.seed, Some(3));
        assert_eq!(d.camera.fov, Some(30.0));
        assert_eq!(d.camera.camera_from, Some([1.0; 3]));
        let sun = d.sun.as_ref().unwrap();
        assert_eq!(sun.sun_dir, Some([0.0, -1.0, 0.0]));
        assert_eq!(sun.sun_irradiance, Some([1.0; 3]));
        assert_eq!(d.volumes[0].g, Some(-0.3));
        assert_eq!(d.volumes[1].g, Some(-0.3));
        assert_eq!(d.volumes[0].albedo, Some(Colour::Rgb([0.5, 0.6, 0.7])));
        assert!(d.environment.is_none(), "no sky field given, none written");
    }

    #[test]
    fn json_overrides_refuse_unknown_names() {
        let o: Overrides = serde_json::from_str(r#"{"spp": 4, "res": "8x4"}"#).unwrap();
        assert_eq!((o.spp, o.res), (Some(4), Some((8, 4))));
        let e = serde_json::from_str::<Overrides>(r#"{"spp": 4, "sampels": 2}"#).unwrap_err();
        assert!(e.to_string().contains("sampels"), "{e}");
    }
}
