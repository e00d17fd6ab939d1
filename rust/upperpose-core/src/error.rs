//! The one error type of the core crate.

/// Everything that can go wrong in the core, with the values that explain it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CoreError {
    /// A numeric argument is NaN or infinite.
    #[error("{name} must be finite, got {}", Num(*value))]
    NotFinite { name: &'static str, value: f64 },
    /// A numeric argument is outside the values it may take.
    #[error("{name} must be {expected}, got {}", Num(*value))]
    OutOfRange {
        name: &'static str,
        expected: &'static str,
        value: f64,
    },
    /// A slice or array has the wrong length or shape.
    #[error("{name} must have shape {expected}, got {got}")]
    InvalidShape {
        name: &'static str,
        expected: String,
        got: String,
    },
    /// A setting (an environment variable, a resource) has a value that cannot be used.
    #[error("{name} must be {expected}, got {got}")]
    BadSetting {
        name: &'static str,
        expected: &'static str,
        got: String,
    },
    /// A region of interest is empty or does not overlap the image.
    #[error(
        "region of interest {roi:?} must be non-empty and lie inside the {width}x{height} image"
    )]
    InvalidRoi {
        roi: (i64, i64, i64, i64),
        width: u32,
        height: u32,
    },
}

/// A value as a message shows it: plainly, but in exponent form when plain would spell out
/// hundreds of digits (1e300, 1e-12).
struct Num(f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0.abs();
        if v != 0.0 && v.is_finite() && !(1e-4..1e9).contains(&v) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// Result with [`CoreError`].
pub type Result<T> = std::result::Result<T, CoreError>;

/// Checks that `value` is finite; `name` names it in the error.
pub fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(CoreError::NotFinite { name, value })
    }
}

/// Checks that `value` is finite and strictly positive.
pub fn positive(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(CoreError::OutOfRange {
            name,
            expected: "> 0",
            value,
        })
    }
}
