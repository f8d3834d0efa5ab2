//! End to end: the `mfh eval` contract for spherical Gaussians (document 003: SG, ASG), driven
//! through `mfh_harness::cli::run` exactly as the binary calls it: every SG/ASG quantity answers
//! `{"value": …}` equal bit for bit to the reference library called directly.

mod eval_support;

use eval_support::{answers, assert_answer, lines, mfh, num, Expect};
use mfh_reference::geometry::{from_spherical, Vec3};
use mfh_reference::sg::{Asg, Sg};
use serde_json::{json, Value};

/// An SG as the contract writes it.
fn sg_json(axis: Vec3, sharpness: f64, amplitude: f64) -> Value {
    json!({"axis": axis, "sharpness": sharpness, "amplitude": amplitude})
}

#[test]
fn spherical_gaussian_quantities_answer_as_the_library_does() {
    let (a_axis, b_axis, v) = (
        from_spherical(0.3, 0.2),
        from_spherical(0.5, 1.9),
        from_spherical(0.4, 0.6),
    );
    let a = Sg::new(a_axis, 8.0, 1.5).unwrap();
    let b = Sg::new(b_axis, 20.0, 0.7).unwrap();
    let (ax, ay, az) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let g = Asg::new(ax, ay, az, [6.0, 15.0], 2.0).unwrap();
    let asg_json = json!({"x": ax, "y": ay, "z": az, "bandwidths": [6.0, 15.0], "amplitude": 2.0});
    let (aj, bj) = (sg_json(a_axis, 8.0, 1.5), sg_json(b_axis, 20.0, 0.7));
    let p = a.product(&b);
    let warped = a.warp(v).unwrap();
    let cases: Vec<(Value, Expect)> = vec![
        (
            json!({"quantity": "sg_eval", "a": aj, "v": v}),
            Ok(num(a.eval(v))),
        ),
        (
            json!({"quantity": "sg_inner", "a": aj, "b": bj}),
            Ok(num(a.inner(&b))),
        ),
        (
            json!({"quantity": "sg_inner", "a": aj, "b": bj, "route": "printed"}),
            Ok(num(a.inner_printed(&b))),
        ),
        (
            json!({"quantity": "sg_inner", "a": aj, "b": bj, "route": "exact"}),
            Ok(num(a.inner_exact(&b))),
        ),
        (
            json!({"quantity": "sg_product", "a": aj, "b": bj}),
            Ok(
                json!({"axis": p.axis().map(num), "sharpness": num(p.sharpness()),
                      "amplitude": num(p.amplitude())}),
            ),
        ),
        (
            json!({"quantity": "sg_integral", "a": aj}),
            Ok(num(a.integral())),
        ),
        (
            json!({"quantity": "sg_integral", "a": aj, "route": "exact"}),
            Ok(num(a.integral_exact())),
        ),
        (
            json!({"quantity": "sg_integral", "a": aj, "cap": 0.7}),
            Ok(num(a.cap_integral(0.7).unwrap())),
        ),
        (
            json!({"quantity": "sg_integral", "a": aj, "cap": 0.7, "route": "cap_product"}),
            Ok(num(a.cap_product(0.7).unwrap().integral())),
        ),
        (
            json!({"quantity": "sg_warp", "a": aj, "o": v}),
            Ok(
                json!({"axis": warped.axis().map(num), "sharpness": num(warped.sharpness()),
                      "amplitude": num(warped.amplitude())}),
            ),
        ),
        (
            json!({"quantity": "asg_eval", "asg": asg_json, "v": v}),
            Ok(num(g.eval(v))),
        ),
        (
            json!({"quantity": "asg_integral", "asg": asg_json}),
            Ok(num(g.integral().unwrap())),
        ),
        (
            json!({"quantity": "asg_integral", "asg": asg_json, "route": "large_bandwidth"}),
            Ok(num(g.integral_large_bandwidth().unwrap())),
        ),
        (
            json!({"quantity": "asg_sg_convolution", "asg": asg_json, "sg": bj}),
            Ok(num(g.convolve_sg(&b).unwrap())),
        ),
        (
            json!({"quantity": "asg_sg_convolution", "asg": asg_json,
                   "sg": {"sharpness": 20.0, "amplitude": 0.7}, "v": b_axis}),
            Ok(num(g.convolve_sg(&b).unwrap())),
        ),
        // Errors: an unknown route, a missing argument, a bad lobe, a bad direction.
        (
            json!({"quantity": "sg_eval", "a": aj, "v": v, "route": "exact"}),
            Err("route"),
        ),
        (json!({"quantity": "sg_inner", "a": aj}), Err("argument")),
        (
            json!({"quantity": "sg_eval", "a": {"axis": a_axis}, "v": v}),
            Err("model"),
        ),
        (
            json!({"quantity": "sg_eval", "a": aj, "v": [0, 0, 2]}),
            Err("argument"),
        ),
    ];
    let queries: Vec<Value> = cases.iter().map(|c| c.0.clone()).collect();
    let r = mfh(&["eval"], &lines(&queries));
    let got = answers(&r);
    assert_eq!(got.len(), cases.len());
    for ((q, e), a) in cases.iter().zip(&got) {
        assert_answer(q, a, e);
    }
    assert_eq!(r.status, 2);
}
