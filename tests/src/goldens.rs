//! The Rust-generated golden file `reference/golden/lambda_dd.json`: certified double-double
//! values of Smith Λ and D (`mfh_harness::oracle::precise`) over a small grid of models and
//! directions, with provenance. Shared by its generator (`examples/generate_goldens.rs`) and
//! the test that proves it current (`tests/goldens.rs`).

use mfh_harness::oracle::precise::{Certified, PreciseError, PreciseModel};
use mfh_reference::geometry::from_spherical;
use mfh_reference::ModelSpec;
use serde_json::{json, Value};
use std::path::PathBuf;

/// The command that regenerates the file.
pub const REGENERATE: &str = "cargo run -p mfh-tests --release --example generate_goldens";

/// The tool named in the provenance block.
pub const TOOL: &str = "mfh-harness oracle::precise, double-double tanh–sinh";

/// Significant digits of the decimal strings.
const DIGITS: usize = 32;

/// The azimuth of every direction (the models are isotropic; a generic φ exercises all three
/// components of the vector).
pub const PHI: f64 = 0.7;

/// Polar angles of the grid: near normal, moderate, oblique, near grazing.
pub const THETAS: [f64; 4] = [0.1, 0.7, 1.2, 1.5];

/// Roughnesses of the grid.
pub const ALPHAS: [f64; 3] = [0.05, 0.3, 1.0];

/// STD shapes of the grid: just above 3/2 (the heavy tail, Λ's integral barely converges),
/// integer, half-integer, general, large.
pub const GAMMAS: [f64; 7] = [1.501, 1.6, 2.0, 2.5, 3.0, 7.3, 1000.0];

/// The path of the golden file.
pub fn golden_path() -> PathBuf {
    let tests = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let root = tests.parent().map_or(tests.clone(), PathBuf::from);
    root.join("reference/golden/lambda_dd.json")
}

/// The models of the grid, in order: Beckmann, GGX, then STD by γ, each by α.
pub fn models() -> Vec<ModelSpec> {
    let mut specs = Vec::new();
    for alpha in ALPHAS {
        let alpha = Some(alpha);
        specs.push(ModelSpec::Beckmann(
            mfh_reference::ndf::beckmann::BeckmannSpec {
                alpha,
                alpha_x: None,
                alpha_y: None,
            },
        ));
        specs.push(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
            alpha,
            alpha_x: None,
            alpha_y: None,
        }));
    }
    for gamma in GAMMAS {
        for alpha in ALPHAS {
            specs.push(ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
                gamma,
                alpha: Some(alpha),
                alpha_x: None,
                alpha_y: None,
            }));
        }
    }
    specs
}

/// One row: the inputs, the certified value (f64, 32-digit decimal, relative bound) and the
/// condition number κ of the quantity (see `PreciseModel::lambda_condition`, `d_condition`).
fn row(spec: &ModelSpec, theta: f64, certified: &Certified, condition: f64) -> Value {
    json!({
        "model": spec,
        "theta": theta,
        "phi": PHI,
        "direction": from_spherical(theta, PHI),
        "value": certified.value,
        "decimal": certified.value_dd.to_decimal(DIGITS),
        "relative_bound": format!("{:.1e}", certified.relative_bound()),
        "condition": format!("{condition:.3e}"),
    })
}

/// The table of one quantity ("lambda" or "d") over the grid, computed now. Values outside the
/// certified range (underflow) are left out, and so are their inputs.
pub fn table(quantity: &str) -> Result<Vec<Value>, PreciseError> {
    let mut rows = Vec::new();
    for spec in models() {
        let model = PreciseModel::from_spec(&spec)?;
        for theta in THETAS {
            let w = from_spherical(theta, PHI);
            let (certified, condition) = if quantity == "lambda" {
                (model.lambda(w), None)
            } else {
                (model.d(w), Some(model.d_condition(w)))
            };
            let certified = match certified {
                Err(PreciseError::Underflow { .. }) => continue,
                other => other?,
            };
            let condition = match condition {
                Some(c) => c,
                None => model.lambda_condition(w)?,
            };
            rows.push(row(&spec, theta, &certified, condition));
        }
    }
    Ok(rows)
}

/// The provenance block.
pub fn provenance() -> Value {
    json!({
        "tool": TOOL,
        "precision": "double-double arithmetic (≈ 106 bits, unit round-off 2^-104); every value \
                      certified to the relative error bound stored with it (≤ 1e-24: the \
                      difference of two tanh–sinh levels plus rounding, see the module docs of \
                      mfh_harness::oracle::precise); decimals rounded to 32 significant digits, \
                      value is the nearest f64",
        "command": REGENERATE,
        "generated_by": "tests/examples/generate_goldens.rs (grid: tests/src/goldens.rs)",
        "checked_by": "tests/tests/goldens.rs (the file is current; the reference closed forms \
                       agree with it)",
        "cross_check": {
            "command": "python3 reference/golden/tools/check_lambda_dd.py",
            "what": "mpmath at 150 digits by routes independent of the quadrature (erfc; A - T \
                     with the incomplete beta function; D's closed forms); fails if a value is \
                     off by more than its stored relative bound",
        },
        "definitions": {
            "lambda": "Smith Lambda(w) = (1/mu) int_mu^inf (q - mu) P2(q) dq, mu = w_z / \
                       sqrt(w_x^2 + w_y^2) (seed 001 eq 5, P2 of eq 15: Beckmann \
                       e^{-q^2/a^2}/(a sqrt(pi)), GGX a^2/(2(a^2+q^2)^{3/2}), STD \
                       N_C/s (1+(q/s)^2)^{1/2-C}, C = gamma, s = alpha sqrt(gamma-1))",
            "d": "D(m) at the unit vector m/|m| (seed 001 eq 2, 10, Table 1)",
            "direction": "the f64 vector from_spherical(theta, phi) of mfh_reference::geometry: \
                          the value is that of this vector, exactly",
            "condition": "kappa = |d ln Lambda / d ln mu| (lambda) or |d ln D / d ln tan^2 theta| \
                          (d): an f64 evaluation from the direction is expected to be off by \
                          ~ kappa * 2.2e-16 on top of its own error",
        },
        "grid": {
            "theta": THETAS,
            "phi": PHI,
            "alpha": ALPHAS,
            "std_gamma": GAMMAS,
            "left_out": "values below 1e-290 (outside the certified range)",
        },
    })
}

/// The whole file, computed now.
pub fn golden_file() -> Result<Value, PreciseError> {
    Ok(json!({
        "provenance": provenance(),
        "lambda": table("lambda")?,
        "d": table("d")?,
    }))
}
