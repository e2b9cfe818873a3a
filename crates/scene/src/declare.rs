//! The machinery behind the one declaration of every setting
//! (`description.rs`): [`declare_settings!`] turns each table's list of
//! settings into
//!
//! - the table's struct of the scene-file format (`RenderSpec`, ...), each
//!   setting an `Option` named by its key, with a getter that applies the
//!   declared default where there is one;
//! - [`SceneDescription`](crate::SceneDescription), the tables together;
//! - [`Overrides`](crate::Overrides): every setting as a flat optional
//!   field (the Python keyword), and `apply`, which writes the given ones
//!   over a description;
//! - with the `clap` feature, one `clap::Args` struct per table, whose
//!   flags' help ends in the declared default;
//! - [`settings`]: each setting's key, keyword, default and help, from
//!   which the README's table is made (and checked), and an example value
//!   per setting, with which a test checks every one reaches the renderer.
//!
//! A setting is therefore added in one place, and cannot be forgotten in
//! any of its forms: a field left out of one would not exist.

use std::path::PathBuf;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{
    DistanceSampling, IntegratorKind, LightSampling, MajorantMode, SamplerKind, Sunward,
    TransmittanceEstimator, VelocityUnit,
};

use crate::values::Colour;

/// One declared setting, for documentation and tests.
#[derive(Clone, Debug, PartialEq)]
pub struct SettingInfo {
    /// The scene file's table (`render`, `volume`, ...).
    pub table: &'static str,
    /// Its key in that table.
    pub key: &'static str,
    /// The field of `Overrides`: the Python keyword.
    pub keyword: &'static str,
    /// What it is (the declaration's doc comment, lines joined).
    pub help: String,
    /// The default as text, where the declaration gives one.
    pub default: Option<String>,
    /// Whether a flag sets it (file-only keys have none).
    pub has_flag: bool,
}

/// A value as the README and `--help` show a default.
pub trait Shown {
    fn shown(&self) -> String;
}

macro_rules! shown_by_display {
    ($($t:ty),*) => {$(
        impl Shown for $t {
            fn shown(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
shown_by_display!(u32, u64, f32, f64, bool, String, Colour);

macro_rules! shown_by_name {
    ($($t:ty),*) => {$(
        impl Shown for $t {
            fn shown(&self) -> String {
                self.name().to_string()
            }
        }
    )*};
}
shown_by_name!(
    LightSampling,
    Sunward,
    DistanceSampling,
    IntegratorKind,
    TransmittanceEstimator,
    MajorantMode,
    SamplerKind,
    VelocityUnit,
    crate::device::Device
);

impl Shown for (u32, u32) {
    fn shown(&self) -> String {
        format!("{}x{}", self.0, self.1)
    }
}

impl<T: Shown, const N: usize> Shown for [T; N] {
    fn shown(&self) -> String {
        self.iter().map(Shown::shown).collect::<Vec<_>>().join(",")
    }
}

impl Shown for PathBuf {
    fn shown(&self) -> String {
        self.display().to_string()
    }
}

impl Shown for Vec<Aov> {
    fn shown(&self) -> String {
        let names: Vec<&str> = self.iter().map(|a| a.name()).collect();
        names.join(",")
    }
}

/// A flag's help: the declaration's doc lines, then its default.
pub fn help(doc: &[&str], default: Option<String>) -> String {
    let text = doc.iter().map(|l| l.trim()).collect::<Vec<_>>().join(" ");
    match default {
        Some(d) => format!("{text} [default: {d}]"),
        None => text,
    }
}

/// `slot = value` where a value was given.
pub(crate) fn set<T: Clone>(slot: &mut Option<T>, value: &Option<T>) {
    if value.is_some() {
        slot.clone_from(value);
    }
}

/// Declares the settings; see the module documentation. Each table is
///
/// ```text
/// /// docs
/// table field_of_the_description (as "toml name")? : Spec, Flags, one|optional|each {
///     /// docs
///     keyword (as "toml key")? : Type (, serde(...))?, flag(clap arg attributes),
///         (default(value) | unset("what absent means"))?, example(value);
///     @file_only { /// docs
///         field (as "toml key")? : Type (= serde(...))?; }
/// }
/// ```
///
/// `one` tables are always there, `optional` ones are written only when a
/// setting of theirs is given, and an `each` table's settings are written
/// into every entry of its array.
macro_rules! declare_settings {
    (
        $(
            $(#[doc = $tdoc:literal])*
            table $tfield:ident $(as $tkey:literal)? : $Spec:ident, $Flags:ident, $mode:ident {
            $(
                $(#[doc = $doc:literal])*
                $field:ident $(as $key:literal)? : $ty:ty
                    $(, serde($($serde:tt)*))?
                    , flag($($flag:tt)*)
                    $(, default($default:expr))?
                    $(, unset($unset:literal))?
                    , example($example:expr);
            )*
            $(
                @file_only {
                    $(
                        $(#[doc = $fdoc:literal])*
                        $ffield:ident $(as $fkey:literal)? : $fty:ty $(= serde($($fserde:tt)*))?;
                    )*
                }
            )?
            }
        )*
    ) => {
        $(
            $(#[doc = $tdoc])*
            #[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
            #[serde(deny_unknown_fields)]
            pub struct $Spec {
                $(
                    $(#[doc = $doc])*
                    $(#[serde(rename = $key)])?
                    $(#[serde($($serde)*)])?
                    pub $field: Option<$ty>,
                )*
                $($(
                    $(#[doc = $fdoc])*
                    $(#[serde(rename = $fkey)])?
                    $(#[serde($($fserde)*)])?
                    pub $ffield: $fty,
                )*)?
            }

            impl $Spec {
                $($(
                    /// The value given, else the declared default.
                    pub fn $field(&self) -> $ty {
                        self.$field.clone().unwrap_or_else(|| $default)
                    }
                )?)*
            }

            #[cfg(feature = "clap")]
            #[derive(clap::Args, Clone, Debug, Default)]
            pub struct $Flags {
                $(
                    #[arg(
                        $($flag)*,
                        help = $crate::declare::help(
                            &[$($doc),*],
                            declare_settings!(@default $ty; $($default)?; $($unset)?),
                        )
                    )]
                    pub $field: Option<$ty>,
                )*
            }

            #[cfg(feature = "clap")]
            impl $Flags {
                /// Writes the flags given into `o`.
                #[allow(unused_variables)]
                pub fn write_into(&self, o: &mut Overrides) {
                    $(
                        $crate::declare::set(&mut o.$field, &self.$field);
                    )*
                }
            }
        )*

        /// A whole scene file: its tables.
        #[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct SceneDescription {
            $(
                $(#[doc = $tdoc])*
                $(#[serde(rename = $tkey)])?
                #[serde(default)]
                pub $tfield: declare_settings!(@table $mode $Spec),
            )*
        }

        /// Settings given by the caller over a scene: every setting with a
        /// flag as a plain optional field, named as its flag (and as the
        /// Python keyword). A field that is set wins over the scene file;
        /// one left `None` leaves the file's value (or the default) in
        /// place. Volume settings apply to every volume.
        #[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct Overrides {
            $($(
                $(#[doc = $doc])*
                $(#[serde($($serde)*)])?
                pub $field: Option<$ty>,
            )*)*
        }

        impl Overrides {
            /// Writes every given field into `d`.
            pub fn apply(&self, d: &mut SceneDescription) {
                $(
                    declare_settings!(@apply $mode, t, (d.$tfield),
                        [$(self.$field.is_some()),*],
                        { $( $crate::declare::set(&mut t.$field, &self.$field); )* });
                )*
                self.apply_exclusive(d);
            }
        }

        /// Every declared setting, table by table.
        pub fn settings() -> Vec<$crate::declare::SettingInfo> {
            let mut all = Vec::new();
            $(
                let table = declare_settings!(@name $tfield $($tkey)?);
                $(
                    all.push($crate::declare::SettingInfo {
                        table,
                        key: declare_settings!(@name $field $($key)?),
                        keyword: stringify!($field),
                        help: $crate::declare::help(&[$($doc),*], None),
                        default: declare_settings!(@default $ty; $($default)?; $($unset)?),
                        has_flag: true,
                    });
                )*
                $($(
                    all.push($crate::declare::SettingInfo {
                        table,
                        key: declare_settings!(@name $ffield $($fkey)?),
                        keyword: "",
                        help: $crate::declare::help(&[$($fdoc),*], None),
                        default: None,
                        has_flag: false,
                    });
                )*)?
            )*
            all
        }

        /// One override per setting with a flag, set to its declared
        /// example (a value other than its default), by keyword.
        pub fn examples() -> Vec<(&'static str, Overrides)> {
            vec![
                $($(
                    (stringify!($field), Overrides {
                        $field: Some($example),
                        ..Default::default()
                    }),
                )*)*
            ]
        }
    };

    (@table one $Spec:ident) => { $Spec };
    (@table optional $Spec:ident) => { Option<$Spec> };
    (@table each $Spec:ident) => { Vec<$Spec> };

    (@apply one, $t:ident, ($($place:tt)*), [$($given:expr),*], { $($body:tt)* }) => {{
        let $t = &mut $($place)*;
        $($body)*
    }};
    (@apply optional, $t:ident, ($($place:tt)*), [$($given:expr),*], { $($body:tt)* }) => {
        if false $(|| $given)* {
            let $t = $($place)*.get_or_insert_with(Default::default);
            $($body)*
        }
    };
    (@apply each, $t:ident, ($($place:tt)*), [$($given:expr),*], { $($body:tt)* }) => {
        #[allow(unused_variables)]
        for $t in &mut $($place)* {
            $($body)*
        }
    };

    (@name $field:ident) => { stringify!($field) };
    (@name $field:ident $key:literal) => { $key };

    (@default $ty:ty; $default:expr; ) => {
        Some(<$ty as $crate::declare::Shown>::shown(&$default))
    };
    (@default $ty:ty; ; $unset:literal) => { Some(String::from($unset)) };
    (@default $ty:ty; ; ) => { None };
}

pub(crate) use declare_settings;
