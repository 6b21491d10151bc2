//! One definition per parameter: a configuration struct declared with [`params!`] carries,
//! for each field, its name, its doc line, its default and its rule, and derives from them
//! `Default`, serde (unknown keys refused), [`Params::validate`] and [`Params::fields`] (the
//! metadata CLI flags, `--help` texts and the docs are generated from).
//!
//! A rule is checked once, here, for every way a value arrives (a task file, a Python dict, a
//! CLI flag); the error names the value by its key path as the user wrote it
//! (`learner.gamma`, `obstacles[1].half_extents[2]`).

use std::fmt;

/// What a parameter's value must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// Anything of the field's type.
    Any,
    /// A finite number.
    Finite,
    /// A finite number > 0.
    Positive,
    /// A finite number ≥ 0.
    NonNegative,
    /// A finite number in an interval.
    Interval {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
        /// The lower bound itself is excluded.
        low_open: bool,
        /// The upper bound itself is excluded.
        high_open: bool,
    },
    /// A number ≥ this (it may be +∞, e.g. a torque cap).
    AtLeast(f64),
    /// An integer in `[min, max]`.
    Count {
        /// Smallest value.
        min: u64,
        /// Largest value.
        max: u64,
    },
    /// A non-empty string or list.
    NonEmpty,
    /// A nested table (or a list of them): its own fields' rules apply.
    Nested,
}

impl Rule {
    /// `[low, high]`.
    pub const fn closed(low: f64, high: f64) -> Self {
        Self::Interval {
            low,
            high,
            low_open: false,
            high_open: false,
        }
    }

    /// `[low, high)`.
    pub const fn closed_open(low: f64, high: f64) -> Self {
        Self::Interval {
            low,
            high,
            low_open: false,
            high_open: true,
        }
    }

    /// `(low, high]`.
    pub const fn open_closed(low: f64, high: f64) -> Self {
        Self::Interval {
            low,
            high,
            low_open: true,
            high_open: false,
        }
    }

    /// `(low, high)`.
    pub const fn open(low: f64, high: f64) -> Self {
        Self::Interval {
            low,
            high,
            low_open: true,
            high_open: true,
        }
    }

    /// An integer in `[min, max]`.
    pub const fn count(min: u64, max: u64) -> Self {
        Self::Count { min, max }
    }

    fn admits(&self, v: f64) -> bool {
        match *self {
            Rule::Finite => v.is_finite(),
            Rule::Positive => v.is_finite() && v > 0.0,
            Rule::NonNegative => v.is_finite() && v >= 0.0,
            Rule::AtLeast(low) => v >= low,
            Rule::Interval {
                low,
                high,
                low_open,
                high_open,
            } => {
                let above = if low_open { v > low } else { v >= low };
                let below = if high_open { v < high } else { v <= high };
                v.is_finite() && above && below
            }
            Rule::Count { min, max } => v >= min as f64 && v <= max as f64,
            Rule::Any | Rule::NonEmpty | Rule::Nested => true,
        }
    }
}

impl fmt::Display for Rule {
    /// The rule as the error messages and docs say it ("must be a finite number > 0").
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Rule::Any | Rule::Nested => write!(f, "any value"),
            Rule::Finite => write!(f, "must be a finite number"),
            Rule::Positive => write!(f, "must be a finite number > 0"),
            Rule::NonNegative => write!(f, "must be a finite number >= 0"),
            Rule::AtLeast(low) => write!(f, "must be >= {} (inf allowed)", Short(low)),
            Rule::Interval {
                low,
                high,
                low_open,
                high_open,
            } => write!(
                f,
                "must lie in {}{}, {}{}",
                if low_open { "(" } else { "[" },
                Short(low),
                Short(high),
                if high_open { ")" } else { "]" }
            ),
            Rule::Count { min, max } => write!(f, "must be an integer in [{min}, {max}]"),
            Rule::NonEmpty => write!(f, "must not be empty"),
        }
    }
}

/// A parameter value that breaks its rule, named by its key path.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path} {message}")]
pub struct ParamError {
    /// The key path as written in a task file (`learner.gamma`, `obstacles[0].center[2]`).
    pub path: String,
    /// What is wrong, with the value ("must lie in [0, 1), got 1.5").
    pub message: String,
}

impl ParamError {
    /// An error at `path` saying `message`.
    pub fn new(path: &str, message: impl Into<String>) -> Self {
        Self {
            path: path.to_string(),
            message: message.into(),
        }
    }
}

/// `parent.child` (or `child` at the top).
pub fn join(parent: &str, child: &str) -> String {
    if parent.is_empty() {
        child.to_string()
    } else {
        format!("{parent}.{child}")
    }
}

/// A value checked against a [`Rule`] at a key path.
pub trait Check {
    /// `Ok` if `self` satisfies `rule`, else the error at `path`.
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError>;
}

fn number(v: f64, rule: &Rule, path: &str) -> Result<(), ParamError> {
    if rule.admits(v) {
        Ok(())
    } else {
        Err(ParamError::new(path, format!("{rule}, got {}", Short(v))))
    }
}

/// A number as a message says it: as written for everyday magnitudes, in exponent form beyond
/// 1e16 (f32's largest is 3.4028234663852886e38, not 39 digits).
struct Short(f64);

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_finite() && self.0.abs() >= 1e16 {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

impl Check for f64 {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        number(*self, rule, path)
    }
}

impl Check for usize {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        number(*self as f64, rule, path)
    }
}

impl Check for u64 {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        number(*self as f64, rule, path)
    }
}

impl Check for bool {
    fn check(&self, _: &Rule, _: &str) -> Result<(), ParamError> {
        Ok(())
    }
}

impl Check for String {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        if *rule == Rule::NonEmpty && self.trim().is_empty() {
            return Err(ParamError::new(path, "is required (an empty string is not allowed)"));
        }
        Ok(())
    }
}

impl<T: Check> Check for Option<T> {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        self.as_ref().map_or(Ok(()), |v| v.check(rule, path))
    }
}

fn each<'a, T: Check + 'a>(items: impl Iterator<Item = &'a T>, rule: &Rule, path: &str) -> Result<(), ParamError> {
    let element_rule = if *rule == Rule::NonEmpty { Rule::Any } else { *rule };
    for (i, item) in items.enumerate() {
        item.check(&element_rule, &format!("{path}[{i}]"))?;
    }
    Ok(())
}

impl<T: Check> Check for Vec<T> {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        if *rule == Rule::NonEmpty && self.is_empty() {
            return Err(ParamError::new(path, "must list at least one entry"));
        }
        each(self.iter(), rule, path)
    }
}

impl<T: Check, const N: usize> Check for [T; N] {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        each(self.iter(), rule, path)
    }
}

impl<T: Check> Check for std::collections::BTreeMap<String, T> {
    fn check(&self, rule: &Rule, path: &str) -> Result<(), ParamError> {
        for (key, value) in self {
            value.check(rule, &join(path, key))?;
        }
        Ok(())
    }
}

/// The type of a parameter as the CLI and the docs name it.
pub trait Kind {
    /// "float", "int", "bool", "str", "float or none", "list", "table", a choice …
    fn kind() -> String;
}

macro_rules! kinds {
    ($($ty:ty => $name:literal),* $(,)?) => {
        $(impl Kind for $ty {
            fn kind() -> String {
                $name.to_string()
            }
        })*
    };
}
kinds!(f64 => "float", usize => "int", u64 => "int", bool => "bool", String => "str");

impl<T: Kind> Kind for Option<T> {
    fn kind() -> String {
        format!("{} or none", T::kind())
    }
}

impl<T: Kind> Kind for Vec<T> {
    fn kind() -> String {
        format!("list of {}", T::kind())
    }
}

impl<T: Kind, const N: usize> Kind for [T; N] {
    fn kind() -> String {
        format!("{N} {}s", T::kind())
    }
}

impl<T: Kind> Kind for std::collections::BTreeMap<String, T> {
    fn kind() -> String {
        format!("table of {}", T::kind())
    }
}

/// One parameter of a [`Params`] struct.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldInfo {
    /// Its key (the Rust field, the task-file key, the CLI flag's last part).
    pub name: &'static str,
    /// Its meaning, from the field's doc comment.
    pub doc: String,
    /// The rule its value must satisfy.
    pub rule: Rule,
    /// Its type as the CLI names it.
    pub kind: String,
}

/// A configuration declared with [`params!`].
pub trait Params: Default {
    /// Every field's name, doc, rule and type, in declaration order.
    fn fields() -> Vec<FieldInfo>;

    /// Checks every field's rule (and, for nested tables, theirs) below key path `path`.
    fn check_fields(&self, path: &str) -> Result<(), ParamError>;

    /// Checks every field: the one validation of this configuration.
    fn validate(&self) -> Result<(), ParamError> {
        self.check_fields("")
    }
}

/// Declares a configuration struct, one line per parameter: doc comment, `name: Type =
/// default => rule`; optionally `check = path;` after the struct names a
/// `fn(&Self, &str) -> Result<(), ParamError>` for rules across fields. Generates the struct
/// (public fields), `Default`, serde (`default`, `deny_unknown_fields`), [`Params`], [`Check`]
/// (so it nests) and [`Kind`] ("table").
#[macro_export]
macro_rules! params {
    (
        $(#[doc = $sdoc:literal])*
        pub struct $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $field:ident : $ty:ty = $default:expr => $rule:expr
            ),* $(,)?
        }
        $(check = $check:path;)?
    ) => {
        $(#[doc = $sdoc])*
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[doc = $doc])*
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self { $($field: $default,)* }
            }
        }

        impl $crate::params::Params for $name {
            fn fields() -> Vec<$crate::params::FieldInfo> {
                vec![$(
                    $crate::params::FieldInfo {
                        name: stringify!($field),
                        doc: [$($doc),*].iter().map(|line: &&str| line.trim()).collect::<Vec<_>>().join(" "),
                        rule: $rule,
                        kind: <$ty as $crate::params::Kind>::kind(),
                    },
                )*]
            }

            fn check_fields(&self, path: &str) -> ::core::result::Result<(), $crate::params::ParamError> {
                $(
                    $crate::params::Check::check(&self.$field, &$rule, &$crate::params::join(path, stringify!($field)))?;
                )*
                $($check(self, path)?;)?
                Ok(())
            }
        }

        impl $crate::params::Check for $name {
            fn check(&self, _: &$crate::params::Rule, path: &str) -> ::core::result::Result<(), $crate::params::ParamError> {
                $crate::params::Params::check_fields(self, path)
            }
        }

        impl $crate::params::Kind for $name {
            fn kind() -> String {
                "table".to_string()
            }
        }
    };
}

/// Declares a string-valued choice: a unit enum (serde names in snake_case) that checks as
/// valid and whose [`Kind`] lists the choices.
#[macro_export]
macro_rules! choice {
    (
        $(#[doc = $sdoc:literal])*
        pub enum $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $variant:ident = $text:literal
            ),* $(,)?
        }
    ) => {
        $(#[doc = $sdoc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
        pub enum $name {
            $(
                $(#[doc = $doc])*
                #[serde(rename = $text)]
                $variant,
            )*
        }

        impl $name {
            /// The name as written in a task file.
            pub fn as_str(self) -> &'static str {
                match self {
                    $(Self::$variant => $text,)*
                }
            }

            /// The choice written `name`, if it is one.
            pub fn from_name(name: &str) -> Option<Self> {
                match name {
                    $($text => Some(Self::$variant),)*
                    _ => None,
                }
            }

            /// The choice written `name` for the argument `what`, or an error listing the choices.
            pub fn parse(what: &str, name: &str) -> ::core::result::Result<Self, $crate::params::ParamError> {
                Self::from_name(name).ok_or_else(|| {
                    $crate::params::ParamError::new(what, format!("must be one of {}, got {name:?}", [$($text),*].join(" | ")))
                })
            }
        }

        impl $crate::params::Check for $name {
            fn check(&self, _: &$crate::params::Rule, _: &str) -> ::core::result::Result<(), $crate::params::ParamError> {
                Ok(())
            }
        }

        impl $crate::params::Kind for $name {
            fn kind() -> String {
                [$($text),*].join(" | ")
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::choice! {
        /// A test choice.
        pub enum Colour {
            /// Red.
            Red = "red",
            /// Dark blue.
            DarkBlue = "dark_blue",
        }
    }

    crate::params! {
        /// A nested test table.
        pub struct Inner {
            /// A count.
            n: usize = 2 => Rule::count(2, 10),
            /// Corners.
            corner: [f64; 3] = [0.0; 3] => Rule::Finite,
        }
    }

    crate::params! {
        /// A test table.
        pub struct Outer {
            /// A rate in (0, 1].
            /// Second line.
            rate: f64 = 0.5 => Rule::open_closed(0.0, 1.0),
            /// A discount in [0, 1).
            gamma: f64 = 0.9 => Rule::closed_open(0.0, 1.0),
            /// A threshold or none.
            threshold: Option<f64> = None => Rule::Positive,
            /// A cap that may be inf.
            cap: f64 = f64::INFINITY => Rule::AtLeast(0.0),
            /// Names.
            names: Vec<String> = vec!["a".into()] => Rule::NonEmpty,
            /// A colour.
            colour: Colour = Colour::Red => Rule::Any,
            /// Inner tables.
            inner: Vec<Inner> = vec![Inner::default()] => Rule::Nested,
        }
        check = at_most_three_names;
    }

    fn at_most_three_names(o: &Outer, path: &str) -> Result<(), ParamError> {
        if o.names.len() > 3 {
            return Err(ParamError::new(&join(path, "names"), "at most 3"));
        }
        Ok(())
    }

    #[test]
    fn rules_name_the_path_and_the_value() {
        assert!(Outer::default().validate().is_ok());
        let bad = |o: Outer| o.validate().unwrap_err().to_string();
        assert_eq!(
            bad(Outer {
                gamma: 1.0,
                ..Outer::default()
            }),
            "gamma must lie in [0, 1), got 1"
        );
        assert_eq!(
            bad(Outer {
                rate: f64::NAN,
                ..Outer::default()
            }),
            "rate must lie in (0, 1], got NaN"
        );
        assert_eq!(
            bad(Outer {
                threshold: Some(-1.0),
                ..Outer::default()
            }),
            "threshold must be a finite number > 0, got -1"
        );
        assert_eq!(
            bad(Outer {
                names: vec![],
                ..Outer::default()
            }),
            "names must list at least one entry"
        );
        let mut inner = Inner::default();
        inner.corner[2] = f64::INFINITY;
        assert_eq!(
            bad(Outer {
                inner: vec![Inner::default(), inner],
                ..Outer::default()
            }),
            "inner[1].corner[2] must be a finite number, got inf"
        );
        assert_eq!(
            bad(Outer {
                names: vec!["a".into(); 4],
                ..Outer::default()
            }),
            "names at most 3"
        );
        assert!(
            Outer {
                cap: 3.0,
                ..Outer::default()
            }
            .validate()
            .is_ok()
        );
    }

    #[test]
    fn fields_carry_docs_rules_and_kinds() {
        let fields = Outer::fields();
        let names: Vec<_> = fields.iter().map(|f| f.name).collect();
        assert_eq!(names, ["rate", "gamma", "threshold", "cap", "names", "colour", "inner"]);
        assert_eq!(fields[0].doc, "A rate in (0, 1]. Second line.");
        assert_eq!(fields[0].rule.to_string(), "must lie in (0, 1]");
        assert_eq!(fields[2].kind, "float or none");
        assert_eq!(fields[5].kind, "red | dark_blue");
        assert_eq!(fields[6].kind, "list of table");
        assert_eq!(Colour::DarkBlue.as_str(), "dark_blue");
        assert_eq!(Colour::from_name("dark_blue"), Some(Colour::DarkBlue));
        assert_eq!(Colour::from_name("DarkBlue"), None);
        assert_eq!(Colour::parse("colour", "red").unwrap(), Colour::Red);
        let wrong = Colour::parse("colour", "blue").unwrap_err().to_string();
        assert_eq!(wrong, r#"colour must be one of red | dark_blue, got "blue""#);
    }
}
