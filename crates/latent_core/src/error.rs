//! The one error type of `latent_core`: every variant says what was wrong and where.

/// Errors raised by the core when its inputs or numerics are unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CoreError {
    /// An array had the wrong shape.
    #[error("{what}: expected shape {expected}, got {got}")]
    Shape {
        /// Which argument.
        what: &'static str,
        /// The shape that was expected, e.g. `(N, 2)`.
        expected: String,
        /// The shape that was given.
        got: String,
    },
    /// An input held NaN or an infinity.
    #[error("{what} contains a non-finite value ({value}) at flat index {index}")]
    NonFinite {
        /// Which argument.
        what: &'static str,
        /// Flat (row-major) index of the first bad value.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// An input that must hold at least one element was empty.
    #[error("{what} is empty")]
    Empty {
        /// Which argument.
        what: &'static str,
    },
    /// A scalar parameter was outside its allowed range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// The kernel matrix could not be factorised, even after adding jitter.
    #[error(
        "kernel matrix ({n}x{n}) is not positive definite even with jitter {jitter:e} added to its diagonal; \
         the inputs may contain duplicate points and the noise variance may be too small"
    )]
    NotPositiveDefinite {
        /// Size of the matrix.
        n: usize,
        /// The largest jitter tried.
        jitter: f64,
    },
    /// A result overflowed float64 although every input was finite (inputs of extreme scale).
    #[error("{what} is not finite although every input is: the inputs' scale overflows float64; rescale them")]
    Overflow {
        /// Which result.
        what: &'static str,
    },
    /// No admissible episode start was found.
    #[error(
        "no admissible start state in {draws} draws: every drawn start was refused by the plant \
         (obstacle, drop, box, or for a frozen test episode the plant's test-start rule) or by \
         variance gating; check the start distribution, the test-start rule and the box"
    )]
    NoValidStart {
        /// How many starts were drawn.
        draws: usize,
    },
    /// No start of a frozen test episode was found, tried before any training.
    #[error(
        "no start of a frozen test episode in {draws} draws, tried before training: every drawn \
         start was refused by the plant's test-start rule (a task's episode.test_start), the start \
         distribution, the box or variance gating; check those, or run without test episodes"
    )]
    NoTestStart {
        /// How many starts were drawn.
        draws: usize,
    },
    /// The caller's cancel flag was set during an episode or its start draws (Ctrl-C).
    #[error("cancelled")]
    Cancelled,
    /// A configuration value broke its rule ([`crate::params`]), named by its key path.
    #[error(transparent)]
    Param(#[from] crate::params::ParamError),
    /// A plant could not be built for a trial (e.g. a bad robot description); the
    /// plant's own error, as text.
    #[error("cannot build the plant: {reason}")]
    Plant {
        /// The plant's error message.
        reason: String,
    },
    /// A call's argument broke its limit (a run argument, a latent box corner, a memory cap);
    /// the message names the argument and the limit.
    #[error("{0}")]
    Argument(String),
    /// An input larger than the core can hold: refused before anything is allocated.
    #[error("{what}: {size} points need a {size}×{size} kernel matrix ({gib:.1} GiB); the limit is {limit} points")]
    TooLarge {
        /// Which argument.
        what: &'static str,
        /// Its number of points.
        size: usize,
        /// The most points allowed ([`crate::gp::MAX_GP_POINTS`]).
        limit: usize,
        /// The memory the kernel matrix would take (GiB).
        gib: f64,
    },
}

/// What kind of failure an error is: what a caller (the Python binding) raises for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A wrong shape, a non-finite value, an impossible value: the caller's input.
    Input,
    /// A computation that could not be carried out stably.
    Numerical,
    /// The caller cancelled (Ctrl-C).
    Cancelled,
}

impl CoreError {
    /// The kind of this error.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Self::Shape { .. }
            | Self::NonFinite { .. }
            | Self::Empty { .. }
            | Self::InvalidParameter { .. }
            | Self::NoValidStart { .. }
            | Self::NoTestStart { .. }
            | Self::Param(_)
            | Self::Plant { .. }
            | Self::Argument(_)
            | Self::TooLarge { .. } => ErrorKind::Input,
            Self::NotPositiveDefinite { .. } | Self::Overflow { .. } => ErrorKind::Numerical,
            Self::Cancelled => ErrorKind::Cancelled,
        }
    }
}

/// Result alias for the core.
pub type Result<T> = std::result::Result<T, CoreError>;

/// Fails with [`CoreError::Shape`] unless `values` holds `len` values, then as [`check_finite`].
pub fn check_vector(what: &'static str, values: &[f64], len: usize) -> Result<()> {
    if values.len() != len {
        return Err(CoreError::Shape {
            what,
            expected: format!("({len},)"),
            got: format!("({},)", values.len()),
        });
    }
    check_finite(what, values)
}

/// Fails with [`CoreError::NonFinite`] at the first NaN or infinity in `values`.
pub fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(CoreError::NonFinite {
            what,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Fails with [`CoreError::InvalidParameter`] unless `value` is finite and > 0.
pub fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(CoreError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        })
    }
}

/// A deserializer's message with Rust's type names as a task file's author would say them
/// (`expected usize` → `expected a whole number ≥ 0`): the one wording of every key's type error.
pub fn plain_types(message: &str) -> String {
    const WORDS: [(&str, &str); 5] = [
        ("usize", "a whole number ≥ 0"),
        ("u64", "a whole number ≥ 0"),
        ("u32", "a whole number ≥ 0"),
        ("i64", "a whole number"),
        ("f64", "a number"),
    ];
    WORDS.iter().fold(message.to_string(), |text, (rust, plain)| {
        let (from, to) = (format!("expected {rust}"), format!("expected {plain}"));
        // Whole words only: "expected u64" must not touch "expected u64s".
        let mut out = String::with_capacity(text.len());
        let mut rest = text.as_str();
        while let Some(i) = rest.find(&from) {
            let end = i + from.len();
            let whole = !rest[end..].starts_with(|c: char| c.is_alphanumeric() || c == '_');
            out.push_str(&rest[..i]);
            out.push_str(if whole { &to } else { &from });
            rest = &rest[end..];
        }
        out.push_str(rest);
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_errors_say_what_a_user_writes() {
        assert_eq!(
            plain_types("invalid value: integer `-1`, expected usize"),
            "invalid value: integer `-1`, expected a whole number ≥ 0"
        );
        assert_eq!(
            plain_types("invalid type: string \"x\", expected f64"),
            "invalid type: string \"x\", expected a number"
        );
        assert_eq!(
            plain_types("expected u64s or expected i64"),
            "expected u64s or expected a whole number"
        );
    }

    #[test]
    fn kinds_sort_input_from_numerics_and_cancel() {
        assert_eq!(
            check_finite("x", &[1.0, f64::NAN]).unwrap_err().kind(),
            ErrorKind::Input
        );
        assert_eq!(CoreError::Argument("n".into()).kind(), ErrorKind::Input);
        let numerical = CoreError::NotPositiveDefinite { n: 2, jitter: 1e-6 };
        assert_eq!(numerical.kind(), ErrorKind::Numerical);
        assert_eq!(CoreError::Overflow { what: "v" }.kind(), ErrorKind::Numerical);
        assert_eq!(CoreError::Cancelled.kind(), ErrorKind::Cancelled);
    }
}
