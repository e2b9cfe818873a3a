//! One declaration per settings enum: each value's name is written once,
//! and scene files (serde), flags (clap's `ValueEnum`, behind the `clap`
//! feature) and reports (`name()`) all spell it from there.

/// Declares a settings enum from its values and their names:
///
/// ```ignore
/// settings_enum! {
///     /// What it chooses.
///     pub enum Choice {
///         /// The default value.
///         #[default]
///         First = "first",
///         Second = "second",
///     }
/// }
/// ```
///
/// It derives `Clone, Copy, Debug, Default, PartialEq, Eq`, serde's
/// `Serialize` and `Deserialize` and (with the `clap` feature) clap's
/// `ValueEnum`, each under the given names, and `name()` returning them.
macro_rules! settings_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $(
                $(#[$vmeta:meta])*
                $variant:ident = $text:literal,
            )+
        }
    ) => {
        $(#[$meta])*
        #[derive(
            Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize,
        )]
        #[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
        $vis enum $name {
            $(
                $(#[$vmeta])*
                #[serde(rename = $text)]
                #[cfg_attr(feature = "clap", value(name = $text))]
                $variant,
            )+
        }

        impl $name {
            /// The value's name, as scene files, flags and reports spell it.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)+
                }
            }
        }
    };
}
