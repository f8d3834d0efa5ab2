//! `mfh eval` for spherical Gaussians and anisotropic spherical Gaussians (document 003): the
//! quantities `sg_eval`, `sg_inner`, `sg_product`, `sg_integral`, `sg_warp`, `asg_eval`,
//! `asg_integral` and `asg_sg_convolution`. These queries carry no `"model"`.
//!
//! An SG is `{"axis": [x, y, z], "sharpness": λ, "amplitude": μ}` (amplitude 1 if left out); an
//! ASG is `{"x": […], "y": […], "z": […], "bandwidths": [λ, μ], "amplitude": c}`. Where the
//! document gives an approximation, it answers by default and `"route": "exact"` gives the
//! value by adaptive quadrature; where it gives an exact closed form, `"exact"` gives the
//! quadrature value of the same quantity (a cross-check), and `"default"` the closed form.
//!
//! | quantity | arguments | routes (default first) |
//! |---|---|---|
//! | `sg_eval` | `a`, `v` | `default` |
//! | `sg_inner` | `a`, `b` | `default` (stable closed form), `printed` (as printed: overflows past λ₁+λ₂ ≈ 709), `exact` |
//! | `sg_product` | `a`, `b` | `default` (→ an SG object) |
//! | `sg_integral` | `a`, optional `cap` (half-angle θ_d ∈ [0, π] of a cap around the axis) | `default`, `exact`; with `cap` also `cap_product` (the integral of §2.2's cap-product lobe, as printed) |
//! | `sg_warp` | `a` (the lobe in half vectors), `o` (the view direction, unit) | `default` (§2.1: p_W = 2(o·p)p − o, λ_W = λ/(4\|p·o\|), μ_W = μ; → an SG object) |
//! | `asg_eval` | `asg`, `v` | `default` |
//! | `asg_integral` | `asg` | `default` (§3.2.1 with F), `large_bandwidth` (π/√(λμ)), `exact` |
//! | `asg_sg_convolution` | `asg`, `sg` (its axis is p; or give p as `v` and leave the axis out) | `default` (§3.2.3), `exact` |

use super::args::{number, numbers, optional_finite, EvalError, UNIT_TOLERANCE};
use mfh_reference::geometry::{is_unit, Vec3};
use mfh_reference::sg::{Asg, Sg};
use serde_json::{json, Map, Value};

/// The SG/ASG quantities this module answers.
pub const QUANTITIES: [&str; 8] = [
    "sg_eval",
    "sg_inner",
    "sg_product",
    "sg_integral",
    "sg_warp",
    "asg_eval",
    "asg_integral",
    "asg_sg_convolution",
];

/// The largest SG sharpness and ASG bandwidth accepted, 1e150: the closed forms form
/// λ₁λ₂ and ‖λ₁p₁ + λ₂p₂‖², which overflow to ∞ (and then NaN, ∞ · 0) past ≈ 1.3e154; no
/// lobe a renderer uses comes near (a mirror lobe is λ ≈ 1e4 … 1e6).
pub const SHARPNESS_MAX: f64 = 1e150;

/// The largest |amplitude| accepted, 1e150: products of two amplitudes stay finite (< 1e300),
/// so an underflowing exponential never meets an infinite amplitude (0 · ∞ = NaN).
pub const AMPLITUDE_MAX: f64 = 1e150;

/// The argument keys each SG/ASG quantity takes (besides `quantity` and `route`); None for a
/// quantity this module does not answer.
pub fn arguments(quantity: &str) -> Option<&'static [&'static str]> {
    Some(match quantity {
        "sg_eval" => &["a", "v"],
        "sg_inner" | "sg_product" => &["a", "b"],
        "sg_integral" => &["a", "cap"],
        "sg_warp" => &["a", "o"],
        "asg_eval" => &["asg", "v"],
        "asg_integral" => &["asg"],
        "asg_sg_convolution" => &["asg", "sg", "v"],
        _ => return None,
    })
}

/// Checks a lobe parameter against its limit; the message names the field and the limit.
fn within(owner: &str, key: &str, value: f64, limit: f64) -> Result<f64, EvalError> {
    if value.abs() <= limit {
        Ok(value)
    } else {
        Err(EvalError::Model(format!(
            "\"{owner}\".\"{key}\" = {value:e} exceeds the limit {limit:e} (beyond it the closed \
             forms overflow)"
        )))
    }
}

/// Answers `quantity` if it is an SG/ASG quantity (None otherwise), with the arguments in `q`
/// and the route `route` (None: the default).
pub fn evaluate(
    quantity: &str,
    q: &Map<String, Value>,
    route: Option<&str>,
) -> Option<Result<Value, EvalError>> {
    if !QUANTITIES.contains(&quantity) {
        return None;
    }
    Some(answer(quantity, q, route))
}

fn answer(quantity: &str, q: &Map<String, Value>, route: Option<&str>) -> Result<Value, EvalError> {
    if let Some(r) = q.get("route") {
        if !(r.is_string() || r.is_null()) {
            return Err(EvalError::Argument("\"route\" must be a string".into()));
        }
    }
    let route = route.unwrap_or("default");
    match quantity {
        "sg_eval" => {
            routes(quantity, route, &["default"])?;
            let a = sg(q, "a", true)?;
            Ok(number(a.eval(vector(q, "v")?)))
        }
        "sg_inner" => {
            routes(quantity, route, &["default", "printed", "exact"])?;
            let (a, b) = (sg(q, "a", true)?, sg(q, "b", true)?);
            Ok(number(match route {
                "printed" => a.inner_printed(&b),
                "exact" => a.inner_exact(&b),
                _ => a.inner(&b),
            }))
        }
        "sg_product" => {
            routes(quantity, route, &["default"])?;
            let p = sg(q, "a", true)?.product(&sg(q, "b", true)?);
            Ok(sg_value(&p))
        }
        "sg_warp" => {
            routes(quantity, route, &["default"])?;
            let w = sg(q, "a", true)?.warp(vector(q, "o")?)?;
            Ok(sg_value(&w))
        }
        "sg_integral" => {
            let a = sg(q, "a", true)?;
            match optional_finite(q, "cap")? {
                None => {
                    routes(quantity, route, &["default", "exact"])?;
                    Ok(number(if route == "exact" {
                        a.integral_exact()
                    } else {
                        a.integral()
                    }))
                }
                Some(theta_d) => {
                    routes(quantity, route, &["default", "exact", "cap_product"])?;
                    Ok(number(match route {
                        "exact" => a.cap_integral_exact(theta_d)?,
                        "cap_product" => a.cap_product(theta_d)?.integral(),
                        _ => a.cap_integral(theta_d)?,
                    }))
                }
            }
        }
        "asg_eval" => {
            routes(quantity, route, &["default"])?;
            Ok(number(asg(q)?.eval(vector(q, "v")?)))
        }
        "asg_integral" => {
            routes(quantity, route, &["default", "large_bandwidth", "exact"])?;
            let g = asg(q)?;
            Ok(number(match route {
                "exact" => g.integral_exact(),
                "large_bandwidth" => g.integral_large_bandwidth()?,
                _ => g.integral()?,
            }))
        }
        "asg_sg_convolution" => {
            routes(quantity, route, &["default", "exact"])?;
            let g = asg(q)?;
            let axis_given = q
                .get("sg")
                .and_then(Value::as_object)
                .is_some_and(|o| o.contains_key("axis"));
            let s = match (axis_given, q.contains_key("v")) {
                (true, true) => {
                    return Err(EvalError::Argument(
                        "give the SG's axis either as \"sg\".\"axis\" or as \"v\", not both".into(),
                    ))
                }
                (false, true) => {
                    let partial = sg(q, "sg", false)?;
                    Sg::new(vector(q, "v")?, partial.sharpness(), partial.amplitude())?
                }
                _ => sg(q, "sg", true)?,
            };
            Ok(number(if route == "exact" {
                g.convolve_sg_exact(&s)
            } else {
                g.convolve_sg(&s)?
            }))
        }
        _ => unreachable!("checked against QUANTITIES"),
    }
}

fn routes(quantity: &str, route: &str, known: &[&str]) -> Result<(), EvalError> {
    if known.contains(&route) {
        Ok(())
    } else {
        Err(EvalError::Route(format!(
            "route {route:?} is not available for {quantity} (known: {})",
            known.join(", ")
        )))
    }
}

fn array3(v: &Value, what: &str) -> Result<Vec3, EvalError> {
    numbers::<3>(v).ok_or_else(|| EvalError::Argument(format!("{what} must be [x, y, z]")))
}

/// An SG as the JSON object the queries take (`{"axis", "sharpness", "amplitude"}`).
fn sg_value(g: &Sg) -> Value {
    json!({
        "axis": g.axis().iter().map(|c| number(*c)).collect::<Vec<_>>(),
        "sharpness": number(g.sharpness()),
        "amplitude": number(g.amplitude()),
    })
}

/// The unit vector `q[key]`.
fn vector(q: &Map<String, Value>, key: &str) -> Result<Vec3, EvalError> {
    let v = q
        .get(key)
        .ok_or_else(|| EvalError::Argument(format!("missing \"{key}\" ([x, y, z])")))?;
    let a = array3(v, &format!("\"{key}\""))?;
    if !is_unit(a, UNIT_TOLERANCE) {
        return Err(EvalError::Argument(format!(
            "\"{key}\" must be a unit vector (got {a:?})"
        )));
    }
    Ok(a)
}

fn object<'a>(
    q: &'a Map<String, Value>,
    key: &str,
    allowed: &[&str],
) -> Result<&'a Map<String, Value>, EvalError> {
    let o = q
        .get(key)
        .ok_or_else(|| EvalError::Argument(format!("missing \"{key}\"")))?
        .as_object()
        .ok_or_else(|| EvalError::Argument(format!("\"{key}\" must be an object")))?;
    if let Some(unknown) = o.keys().find(|k| !allowed.contains(&k.as_str())) {
        return Err(EvalError::Model(format!(
            "unknown key {unknown:?} in \"{key}\" (known: {})",
            allowed.join(", ")
        )));
    }
    Ok(o)
}

fn model_number(o: &Map<String, Value>, owner: &str, key: &str) -> Result<f64, EvalError> {
    o.get(key)
        .ok_or_else(|| EvalError::Model(format!("\"{owner}\" is missing \"{key}\"")))?
        .as_f64()
        .ok_or_else(|| EvalError::Model(format!("\"{owner}\".\"{key}\" must be a number")))
}

/// The SG `q[key]`; without `need_axis`, a missing axis is +z (the caller supplies its own).
fn sg(q: &Map<String, Value>, key: &str, need_axis: bool) -> Result<Sg, EvalError> {
    let o = object(q, key, &["axis", "sharpness", "amplitude"])?;
    let axis = match o.get("axis") {
        Some(v) => array3(v, &format!("\"{key}\".\"axis\""))?,
        None if !need_axis => [0.0, 0.0, 1.0],
        None => return Err(EvalError::Model(format!("\"{key}\" is missing \"axis\""))),
    };
    let sharpness = model_number(o, key, "sharpness")?;
    let amplitude = match o.get("amplitude") {
        None => 1.0,
        Some(_) => model_number(o, key, "amplitude")?,
    };
    let sg = Sg::new(axis, sharpness, amplitude)?;
    within(key, "sharpness", sharpness, SHARPNESS_MAX)?;
    within(key, "amplitude", amplitude, AMPLITUDE_MAX)?;
    Ok(sg)
}

/// The ASG `q["asg"]`.
fn asg(q: &Map<String, Value>) -> Result<Asg, EvalError> {
    let o = object(q, "asg", &["x", "y", "z", "bandwidths", "amplitude"])?;
    let frame = |k: &str| -> Result<Vec3, EvalError> {
        let v = o
            .get(k)
            .ok_or_else(|| EvalError::Model(format!("\"asg\" is missing \"{k}\"")))?;
        array3(v, &format!("\"asg\".\"{k}\""))
    };
    let bandwidths = o
        .get("bandwidths")
        .and_then(numbers::<2>)
        .ok_or_else(|| EvalError::Model("\"asg\".\"bandwidths\" must be [λ, μ]".into()))?;
    let amplitude = match o.get("amplitude") {
        None => 1.0,
        Some(_) => model_number(o, "asg", "amplitude")?,
    };
    for b in bandwidths {
        if b.is_finite() {
            within("asg", "bandwidths", b, SHARPNESS_MAX)?;
        }
    }
    if amplitude.is_finite() {
        within("asg", "amplitude", amplitude, AMPLITUDE_MAX)?;
    }
    Ok(Asg::new(
        frame("x")?,
        frame("y")?,
        frame("z")?,
        bandwidths,
        amplitude,
    )?)
}

#[cfg(test)]
mod tests {
    use crate::eval::testing::{error_kind, value};
    use mfh_reference::sg::{Asg, Sg};

    const A: &str = r#"{"axis":[0,0,1],"sharpness":10,"amplitude":2}"#;
    const B: &str = r#"{"axis":[0,0.6,0.8],"sharpness":3}"#;
    const ASG: &str = r#"{"x":[1,0,0],"y":[0,1,0],"z":[0,0,1],"bandwidths":[8,3],"amplitude":1.5}"#;

    #[test]
    fn sg_quantities_match_the_library() {
        let a = Sg::new([0.0, 0.0, 1.0], 10.0, 2.0).unwrap();
        let b = Sg::new([0.0, 0.6, 0.8], 3.0, 1.0).unwrap();
        let v = value(&format!(
            r#"{{"quantity":"sg_eval","a":{A},"v":[0,0.6,0.8]}}"#
        ));
        assert_eq!(v.as_f64().unwrap(), a.eval([0.0, 0.6, 0.8]));
        let v = value(&format!(r#"{{"quantity":"sg_inner","a":{A},"b":{B}}}"#));
        assert_eq!(v.as_f64().unwrap(), a.inner(&b));
        let exact = value(&format!(
            r#"{{"quantity":"sg_inner","a":{A},"b":{B},"route":"exact"}}"#
        ));
        assert!((exact.as_f64().unwrap() / a.inner(&b) - 1.0).abs() < 1e-10);
        let p = value(&format!(r#"{{"quantity":"sg_product","a":{A},"b":{B}}}"#));
        assert_eq!(p["sharpness"].as_f64().unwrap(), a.product(&b).sharpness());
        assert_eq!(p["axis"].as_array().unwrap().len(), 3);
        let i = value(&format!(r#"{{"quantity":"sg_integral","a":{A}}}"#));
        assert_eq!(i.as_f64().unwrap(), a.integral());
        let c = value(&format!(
            r#"{{"quantity":"sg_integral","a":{A},"cap":0.5}}"#
        ));
        assert_eq!(c.as_f64().unwrap(), a.cap_integral(0.5).unwrap());
        let printed = value(&format!(
            r#"{{"quantity":"sg_integral","a":{A},"cap":0.5,"route":"cap_product"}}"#
        ));
        assert!(printed.as_f64().unwrap() > c.as_f64().unwrap());
    }

    #[test]
    fn sg_warp_is_the_library_warp() {
        // Document 003 §2.1: the lobe warp from half vectors to light directions for view o.
        let a = Sg::new([0.0, 0.0, 1.0], 10.0, 2.0).unwrap();
        let o = [0.6, 0.0, 0.8];
        let w = value(&format!(
            r#"{{"quantity":"sg_warp","a":{A},"o":[0.6,0,0.8]}}"#
        ));
        let want = a.warp(o).unwrap();
        assert_eq!(w["sharpness"].as_f64().unwrap(), want.sharpness());
        assert_eq!(w["amplitude"].as_f64().unwrap(), want.amplitude());
        // λ_W = λ/(4|p·o|) = 10/3.2, p_W = 2(o·p)p − o = (−0.6, 0, 0.8).
        assert!((w["sharpness"].as_f64().unwrap() - 3.125).abs() < 1e-15);
        let axis: Vec<f64> = w["axis"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        assert!((axis[0] + 0.6).abs() < 1e-15 && axis[1] == 0.0 && (axis[2] - 0.8).abs() < 1e-15);
        // p ⊥ o: λ_W would be infinite; o not unit; an unknown route.
        assert_eq!(
            error_kind(&format!(r#"{{"quantity":"sg_warp","a":{A},"o":[1,0,0]}}"#)),
            "argument"
        );
        assert_eq!(
            error_kind(&format!(r#"{{"quantity":"sg_warp","a":{A},"o":[0,0,2]}}"#)),
            "argument"
        );
        assert_eq!(
            error_kind(&format!(
                r#"{{"quantity":"sg_warp","a":{A},"o":[0,0,1],"route":"exact"}}"#
            )),
            "route"
        );
    }

    #[test]
    fn asg_quantities_default_to_the_document_and_exact_on_request() {
        let g = Asg::new(
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [8.0, 3.0],
            1.5,
        )
        .unwrap();
        let v = value(&format!(
            r#"{{"quantity":"asg_eval","asg":{ASG},"v":[0,0.6,0.8]}}"#
        ));
        assert_eq!(v.as_f64().unwrap(), g.eval([0.0, 0.6, 0.8]));
        let d = value(&format!(r#"{{"quantity":"asg_integral","asg":{ASG}}}"#));
        assert_eq!(d.as_f64().unwrap(), g.integral().unwrap());
        let e = value(&format!(
            r#"{{"quantity":"asg_integral","asg":{ASG},"route":"exact"}}"#
        ));
        assert_eq!(e.as_f64().unwrap(), g.integral_exact());
        let s = Sg::new([0.0, 0.6, 0.8], 20.0, 1.0).unwrap();
        let c = value(&format!(
            r#"{{"quantity":"asg_sg_convolution","asg":{ASG},"sg":{{"axis":[0,0.6,0.8],"sharpness":20}}}}"#
        ));
        assert_eq!(c.as_f64().unwrap(), g.convolve_sg(&s).unwrap());
        let via_v = value(&format!(
            r#"{{"quantity":"asg_sg_convolution","asg":{ASG},"sg":{{"sharpness":20}},"v":[0,0.6,0.8]}}"#
        ));
        assert_eq!(via_v, c);
        let exact = value(&format!(
            r#"{{"quantity":"asg_sg_convolution","asg":{ASG},"sg":{{"axis":[0,0.6,0.8],"sharpness":20}},"route":"exact"}}"#
        ));
        assert!((exact.as_f64().unwrap() / g.convolve_sg_exact(&s) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn errors_have_kinds() {
        assert_eq!(
            error_kind(&format!(
                r#"{{"quantity":"sg_inner","a":{A},"b":{B},"route":"table1"}}"#
            )),
            "route"
        );
        assert_eq!(
            error_kind(&format!(r#"{{"quantity":"sg_eval","a":{A},"v":[0,0,2]}}"#)),
            "argument"
        );
        assert_eq!(
            error_kind(r#"{"quantity":"sg_eval","a":{"axis":[0,0,1],"sharpness":-1},"v":[0,0,1]}"#),
            "model"
        );
        assert_eq!(
            error_kind(r#"{"quantity":"sg_eval","a":{"axis":[0,0,1],"sharpnes":1},"v":[0,0,1]}"#),
            "model"
        );
        assert_eq!(
            error_kind(&format!(r#"{{"quantity":"sg_integral","a":{A},"cap":4}}"#)),
            "argument"
        );
        assert_eq!(
            error_kind(
                r#"{"quantity":"asg_eval","asg":{"x":[1,0,0],"y":[1,0,0],"z":[0,0,1],"bandwidths":[1,1]},"v":[0,0,1]}"#
            ),
            "model"
        );
        assert_eq!(
            error_kind(&format!(
                r#"{{"quantity":"asg_sg_convolution","asg":{ASG},"sg":{B},"v":[0,0,1]}}"#
            )),
            "argument"
        );
        assert_eq!(
            error_kind(&format!(
                r#"{{"quantity":"sg_product","a":{A},"b":{B},"route":3}}"#
            )),
            "argument"
        );
        assert!(super::evaluate("d", &serde_json::Map::new(), None).is_none());
    }
}
