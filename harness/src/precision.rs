//! The working precision of an implementation under audit: a renderer computing its
//! model in float32 answers with float32 rounding noise, and every value tolerance and every
//! oracle's rounding floor is a function of it (`tolerance::Tolerance::at`,
//! `oracle::quadrature::Accuracy::at`).
//!
//! The subject carries the declared precision and every record says what it was judged at. Its
//! ε sets the float32 rows of the tolerances (`tolerance/precision.rs`; the BSDF checks' `_f32`
//! rows in `tolerance/bsdf.rs`) and the oracles' rounding floors (`oracle.noise_floor` in a
//! record, absent at f64). A float32 model audited as f64 is found by
//! `audit/precision_probe.rs`, which writes the `audit.precision` record.

use serde::{Deserialize, Serialize};

/// The arithmetic an implementation computes in (its answers may still be handed over as f64).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// IEEE binary64 (ε = 2.2e-16): mfh's reference models and the default.
    #[default]
    F64,
    /// IEEE binary32 (ε = 1.2e-7): pbrt-v4's default `Float`, Mitsuba 3's shipped variants,
    /// game engines.
    F32,
}

impl Precision {
    /// Every precision, in order.
    pub const ALL: [Precision; 2] = [Precision::F64, Precision::F32];

    /// The machine epsilon of the format (the gap from 1 to the next value: 2^−52 or 2^−23).
    pub fn epsilon(self) -> f64 {
        match self {
            Precision::F64 => f64::EPSILON,
            Precision::F32 => f64::from(f32::EPSILON),
        }
    }

    /// The name records and the protocol use: `f64` or `f32`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }

    /// Whether `x` is a value of the format (always for f64; for f32, `x` survives a round
    /// trip through f32 exactly).
    pub fn represents(self, x: f64) -> bool {
        match self {
            Precision::F64 => true,
            Precision::F32 => f64::from(x as f32) == x || x.is_nan(),
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Precision {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "f64" => Ok(Precision::F64),
            "f32" => Ok(Precision::F32),
            other => Err(format!(
                "precision {other:?} is not one of \"f64\", \"f32\""
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_epsilons_are_the_formats() {
        for p in Precision::ALL {
            assert_eq!(p.name().parse::<Precision>(), Ok(p));
            assert_eq!(serde_json::to_string(&p).unwrap(), format!("\"{p}\""));
        }
        assert!("f16".parse::<Precision>().unwrap_err().contains("f16"));
        assert_eq!(Precision::F32.epsilon(), 2f64.powi(-23));
        assert!(Precision::F32.represents(0.5) && !Precision::F32.represents(0.1));
        assert!(Precision::F64.represents(0.1));
    }
}
