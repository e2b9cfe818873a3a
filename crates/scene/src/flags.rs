//! The command-line form of [`Overrides`]: the flags of each table, as
//! declared in `description.rs`, that the `cirrus` binary and the
//! benchmarks share, so their flags cannot drift apart. A flag left out is
//! `None`, so it never hides a scene file's value; each flag's help ends in
//! its declared default.

use std::path::PathBuf;

use crate::description::{
    CameraFlags, EnvironmentFlags, OutputFlags, RenderFlags, SunFlags, VolumeFlags,
};
use crate::overrides::Overrides;

/// What to render and how: every flag but the outputs.
#[derive(clap::Args, Clone, Debug)]
pub struct SceneFlags {
    /// A .vdb, .nvdb or .cbrk file, a scene file (.toml) or a USD stage (.usd, .usda, .usdc, .usdz).
    pub file: PathBuf,
    #[command(flatten)]
    pub render: RenderFlags,
    #[command(flatten)]
    pub camera: CameraFlags,
    #[command(flatten)]
    pub sun: SunFlags,
    #[command(flatten)]
    pub environment: EnvironmentFlags,
    #[command(flatten)]
    pub volume: VolumeFlags,
}

impl SceneFlags {
    /// The flags given, as overrides (outputs left unset).
    pub fn overrides(&self) -> Overrides {
        let mut o = Overrides::default();
        self.render.write_into(&mut o);
        self.camera.write_into(&mut o);
        self.sun.write_into(&mut o);
        self.environment.write_into(&mut o);
        self.volume.write_into(&mut o);
        o
    }
}

/// The flag that sets the setting whose keyword is `keyword`, as `--help`
/// shows it (`-o, --output`), if any.
fn flag_of(command: &clap::Command, keyword: &str) -> Option<String> {
    let arg = command.get_arguments().find(|a| a.get_id() == keyword)?;
    let long = arg.get_long().map(|l| format!("--{l}"));
    let short = arg.get_short().map(|s| format!("-{s}"));
    Some(
        [short, long]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join(", "),
    )
}

/// The README's table of settings, made from their declaration: one row
/// per setting with its scene-file key, flag, Python keyword, default and
/// help.
pub fn settings_table() -> String {
    use clap::Args;
    let command = OutputFlags::augment_args(SceneFlags::augment_args(clap::Command::new("render")));
    let mut out = String::from(
        "| scene file | flag | Python | default | what it is |\n| --- | --- | --- | --- | --- |\n",
    );
    for s in crate::settings() {
        let table = match s.table {
            "volume" | "light" => format!("[[{}]]", s.table),
            t => format!("[{t}]"),
        };
        let code = |x: &str| format!("`{x}`");
        let flag = match s.has_flag {
            true => flag_of(&command, s.keyword).map_or_else(|| "?".into(), |f| code(&f)),
            false => "(file only)".into(),
        };
        let keyword = match s.has_flag {
            true => code(&format!("{}=", s.keyword)),
            false => String::new(),
        };
        let help = s.help.replace('|', "\\|");
        let default = s.default.unwrap_or_default().replace('|', "\\|");
        out.push_str(&format!(
            "| `{table} {}` | {flag} | {keyword} | {default} | {help} |\n",
            s.key
        ));
    }
    out
}
