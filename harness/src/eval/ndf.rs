//! `mfh eval`'s model quantities: D, Λ, G1, G2, the slope distribution, the samplers and
//! their pdfs, the visible-slope moments (the query carries a `"model"` spec).

use super::args::{
    direction, finite, no_route, number, optional_finite, optional_vector, unit_square,
    visible_incidence, EvalError,
};
use mfh_reference::{Masking, Model, QueryError};
use serde_json::{json, Map, Value};

fn unsupported(model: &dyn Model, quantity: &str) -> EvalError {
    if matches!(quantity, "lambda" | "g1" | "g2") {
        if let Some(why) = model.spec().smith_limit() {
            return EvalError::Unsupported(format!(
                "{} does not support {quantity}: {why}",
                model.family()
            ));
        }
    }
    QueryError::Unsupported {
        family: model.family().to_string(),
        quantity: quantity.to_string(),
    }
    .into()
}

/// The model quantities `mfh eval` answers (the SG/ASG ones are [`super::sg::QUANTITIES`]).
pub const QUANTITIES: [&str; 14] = [
    "d",
    "lambda",
    "g1",
    "g2",
    "p22",
    "p2",
    "slope_moment",
    "variance",
    "excess_kurtosis",
    "sample_wm",
    "pdf_wm",
    "visible_moments",
    "sample_wm_visible",
    "pdf_wm_visible",
];

/// The argument keys each model quantity takes (besides `model`, `quantity`, `route`); None
/// for an unknown quantity.
pub fn arguments(quantity: &str) -> Option<&'static [&'static str]> {
    Some(match quantity {
        "d" | "pdf_wm" => &["m", "theta", "phi"],
        "lambda" | "visible_moments" => &["w", "theta", "phi"],
        "g1" => &["w", "theta", "phi", "m"],
        "g2" => &[
            "wo", "theta_o", "phi_o", "wi", "theta_i", "phi_i", "m", "masking",
        ],
        "p22" => &["p", "q"],
        "p2" => &["q", "phi"],
        "slope_moment" => &["k", "phi"],
        "variance" => &["phi"],
        "excess_kurtosis" => &[],
        "sample_wm" => &["u"],
        "sample_wm_visible" => &["wi", "theta_i", "phi_i", "u"],
        "pdf_wm_visible" => &["wi", "theta_i", "phi_i", "m", "theta", "phi"],
        _ => return None,
    })
}

pub(crate) fn evaluate_quantity(
    model: &dyn Model,
    quantity: &str,
    q: &Map<String, Value>,
    route: Option<&str>,
) -> Result<Value, EvalError> {
    match quantity {
        "d" => {
            no_route(route, quantity)?;
            Ok(number(model.d(direction(q, "m")?)))
        }
        "lambda" => {
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            Ok(number(match route {
                None => smith.lambda(w),
                Some(r) => smith.lambda_route(w, r)?,
            }))
        }
        "g1" => {
            no_route(route, quantity)?;
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            let m = optional_vector(q, "m")?.unwrap_or([0.0, 0.0, 1.0]);
            Ok(number(smith.g1(w, m)))
        }
        "g2" => {
            no_route(route, quantity)?;
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wo = direction(q, "wo")?;
            let wi = direction(q, "wi")?;
            let m = optional_vector(q, "m")?.unwrap_or([0.0, 0.0, 1.0]);
            let masking: Masking = match q.get("masking") {
                None => Masking::HeightCorrelated,
                Some(v) => serde_json::from_value(v.clone()).map_err(|_| {
                    EvalError::Argument(
                        "\"masking\" must be \"uncorrelated\" or \"height_correlated\"".into(),
                    )
                })?,
            };
            Ok(number(smith.g2(wo, wi, m, masking)))
        }
        "p22" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            Ok(number(slopes.p22(finite(q, "p")?, finite(q, "q")?)))
        }
        "p2" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            let phi = optional_finite(q, "phi")?.unwrap_or(0.0);
            Ok(number(slopes.p2(finite(q, "q")?, phi)))
        }
        "slope_moment" | "variance" | "excess_kurtosis" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            let phi = optional_finite(q, "phi")?.unwrap_or(0.0);
            let v = match quantity {
                "slope_moment" => {
                    let k = q.get("k").and_then(Value::as_u64).ok_or_else(|| {
                        EvalError::Argument("\"k\" must be a non-negative integer".into())
                    })?;
                    let k = u32::try_from(k)
                        .map_err(|_| EvalError::Argument("\"k\" is too large".into()))?;
                    slopes.slope_moment(k, phi)
                }
                "variance" => slopes.variance(phi),
                _ => slopes.excess_kurtosis(),
            };
            Ok(v.map(number).unwrap_or(Value::Null))
        }
        "sample_wm" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let m = sampler.sample_wm(unit_square(q)?);
            Ok(Value::Array(m.iter().map(|c| number(*c)).collect()))
        }
        "sample_wm_visible" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_visible_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wi = visible_incidence(q)?;
            let m = sampler.sample_wm_visible(wi, unit_square(q)?);
            Ok(Value::Array(m.iter().map(|c| number(*c)).collect()))
        }
        "pdf_wm_visible" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_visible_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wi = visible_incidence(q)?;
            Ok(number(sampler.pdf_wm_visible(wi, direction(q, "m")?)))
        }
        "pdf_wm" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            Ok(number(sampler.pdf_wm(direction(q, "m")?)))
        }
        "visible_moments" => {
            let moments = model
                .as_visible_moments()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            let v = match route {
                None => moments.visible_moments(w)?,
                Some(r) => moments.visible_moments_route(w, r)?,
            };
            Ok(json!({
                "mean": [number(v.mean[0]), number(v.mean[1])],
                "cov": [
                    [number(v.cov[0][0]), number(v.cov[0][1])],
                    [number(v.cov[1][0]), number(v.cov[1][1])]
                ],
            }))
        }
        other => Err(EvalError::Argument(format!(
            "unknown quantity {other:?} (known: {}, the SG/ASG quantities {} and the BSDF \
             quantities {})",
            QUANTITIES.join(", "),
            super::sg::QUANTITIES.join(", "),
            super::bsdf::QUANTITIES.join(", ")
        ))),
    }
}

#[cfg(test)]
mod tests {
    /// `QUANTITIES` and `arguments` name the same quantities.
    #[test]
    fn every_quantity_has_its_argument_keys() {
        for q in super::QUANTITIES {
            assert!(super::arguments(q).is_some(), "{q}");
        }
        assert!(super::arguments("unknown").is_none());
    }
}
