//! The one error type of `sim`: every variant says what was wrong and where.

/// Errors raised by the plants when their inputs are unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// An array had the wrong shape.
    #[error("{what}: expected shape {expected}, got {got}")]
    Shape {
        /// Which argument.
        what: &'static str,
        /// The shape that was expected, e.g. `(N, 4)`.
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
    /// A hand target lies outside the annulus an arm can reach.
    #[error(
        "{arm} hand target of row {row} is unreachable: {distance:.6} m from the shoulder, \
         the arm reaches from {min:.6} m to {max:.6} m"
    )]
    Unreachable {
        /// `"left"` or `"right"`.
        arm: &'static str,
        /// Row (point index) of the batch, 0 for a single target.
        row: usize,
        /// Distance from the shoulder to the target.
        distance: f64,
        /// Smallest reachable distance, `|l1 − l2|`.
        min: f64,
        /// Largest reachable distance, `l1 + l2`.
        max: f64,
    },
}

/// Result alias for the plants.
pub type Result<T> = std::result::Result<T, SimError>;

/// Fails with [`SimError::NonFinite`] at the first NaN or infinity in `values`.
pub fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(SimError::NonFinite { what, index, value: values[index] }),
        None => Ok(()),
    }
}
