//! The float32 examples of the external protocol: the C++ GGX of
//! `examples/external/cpp/` (`ggx_float.cpp` on the header-only helper `mfh_protocol.hpp`,
//! built here with the machine's g++) and the float32 numpy GGX (`ggx_f32_numpy.py`).
//!
//! What runs today: both examples describe themselves (`"precision":"f32"`), speak versions 1
//! and 2, and agree with mfh's reference closed forms and samplers to float32 accuracy through
//! the protocol; their planted defects are live (the values they change differ from the
//! reference); the C++ helper answers every malformed request with an error naming what is
//! wrong and keeps serving.
//!
//! The `ci` audits at the declared `"precision":"f32"` (ε32 tolerance budgets, oracles that stop
//! at the implementation's rounding floor): the clean examples pass and each defect fails on
//! its named check.

#[path = "external/common.rs"]
mod common;

use common::{example, require_numpy, root, run};
use mfh_harness::external::ExternalModel;
use mfh_reference::model::{NormalSampler, Smith, VisibleNormalSampler};
use mfh_reference::ndf::Ggx;
use mfh_reference::{Ndf, Vec3};
use serde_json::Value;
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The flags the C++ example is built with (`-Werror`-free: the test asserts no warnings
/// itself, so that the message quotes them).
const CXX_FLAGS: [&str; 5] = ["-std=c++17", "-O2", "-Wall", "-Wextra", "-pedantic"];

/// Builds `examples/external/cpp/ggx_float.cpp` with g++ (once per test process, and once per
/// content of the sources and flags: the binary's name carries their hash, so concurrent test
/// processes reuse it or race only to rename identical files into place). Fails, naming the
/// remedy, when g++ is missing or the build fails or warns.
fn cpp_example() -> PathBuf {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT
        .get_or_init(|| {
            let dir = root().join("examples/external/cpp");
            let source = dir.join("ggx_float.cpp");
            let mut hash = DefaultHasher::new();
            for file in ["ggx_float.cpp", "mfh_protocol.hpp"] {
                std::fs::read(dir.join(file))
                    .unwrap_or_else(|e| panic!("{file}: {e}"))
                    .hash(&mut hash);
            }
            CXX_FLAGS.hash(&mut hash);
            let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mfh-cpp-examples");
            std::fs::create_dir_all(&out).unwrap();
            let exe = out.join(format!("ggx_float-{:016x}", hash.finish()));
            if exe.exists() {
                return exe;
            }
            let partial = out.join(format!("ggx_float.{}.partial", std::process::id()));
            let t = Instant::now();
            let built = Command::new("g++")
                .args(CXX_FLAGS)
                .arg("-o")
                .arg(&partial)
                .arg(&source)
                .output()
                .unwrap_or_else(|e| {
                    panic!(
                        "g++ could not run ({e}); .ci/run installs it (apt-get install g++); \
                         without CI=true the C++ tests are ignored where g++ is absent"
                    )
                });
            let stderr = String::from_utf8_lossy(&built.stderr);
            assert!(
                built.status.success(),
                "g++ failed on ggx_float.cpp:\n{stderr}"
            );
            assert!(
                stderr.trim().is_empty(),
                "g++ {} warns on ggx_float.cpp:\n{stderr}",
                CXX_FLAGS.join(" ")
            );
            std::fs::rename(&partial, &exe).unwrap();
            eprintln!(
                "built {} in {:.1} s",
                exe.display(),
                t.elapsed().as_secs_f64()
            );
            exe
        })
        .clone()
}

/// The command that runs the C++ example with `args`.
fn cpp_command(args: &str) -> String {
    format!("{} {args}", cpp_example().display())
        .trim_end()
        .to_string()
}

/// The float32 unit roundoff 2⁻²⁴ ≈ 6.0e-8.
const F32_EPS: f64 = 5.960_464_477_539_063e-8;

/// Relative error bound of D, Λ, G1 and pdf_wm against the f64 reference: the inputs rounded to
/// float (ε each), α rounded to float (ε), and ~10 float operations on the way (sums of
/// positive terms, products, one square root; ≤ 1 ε each): ~20 ε = 1.2e-6 by the bound, 6.7e-7
/// measured over the directions below (α = 0.3 and (0.1, 0.4)). 40 ε = 2.4e-6.
const VALUE_TOLERANCE: f64 = 40.0 * F32_EPS;

/// Absolute bound on a sampled unit vector's components against the reference sampler's for
/// the same u ∈ [0.001, 0.999]²: float rounding (of u and along the map) is magnified where the
/// map is steep. Normal sampling: |∂m/∂u| ≤ ~60 near u₂ = 0.999 (slope radius √(u/(1−u))),
/// 60 ε ≈ 4e-6; measured 1.4e-6. Visible sampling: near the disk's rim (u₁ → 0.999) the lift
/// √(1 − r²) ≈ 0.03 magnifies the rounding of r² by 1/(2 · 0.03) and the unstretch by
/// 1/α_min (10 at α = 0.1): ~160 ε ≈ 1e-5; measured 9.6e-6 (α = (0.1, 0.4), θi = 0.001).
/// 3e-5: 3× the worst measured.
const SAMPLE_TOLERANCE: f64 = 3e-5;

/// The float32 sampler's density against its `pdf_wm` (what `sampling.pdf_jacobian` measures):
/// at most this relative difference for a correct sampler. The density is 1/|∂m/∂u₁ × ∂m/∂u₂|
/// by Richardson-extrapolated central differences with steps 1e-2 and 5e-3 in u ∈ [0.05, 0.95]²:
/// truncation ~3e-5 (the f64 `ggx_numpy.py` shows 2.8e-5 with these steps), float rounding
/// ε/h ≈ 1e-5; measured 2.5e-5 (α = 0.3) and 3.8e-5 (α = (0.1, 0.4)) for both float32
/// examples. 1e-4.
const JACOBIAN_CLEAN: f64 = 1e-4;

/// The least such difference that shows the exponent defect (slope radius ρ^1.001): its
/// density is off by ~0.1 % (measured 1.6e-3 at worst, 7.4e-4 median, over the same points).
const JACOBIAN_DEFECT: f64 = 5e-4;

/// The worst relative difference between the density of `model`'s map u ↦ sample_wm(u) and
/// its pdf_wm, over 256 quasi-random u in [0.05, 0.95]² (through the protocol, in batches).
fn jacobian_error(model: &ExternalModel) -> f64 {
    let u: Vec<[f64; 2]> = uniforms(256)
        .iter()
        .map(|&[a, b]| [0.05 + 0.9 * a, 0.05 + 0.9 * b])
        .collect();
    let sample = |u: &[[f64; 2]]| {
        let mut m = vec![[0.0; 3]; u.len()];
        NormalSampler::sample_wm_batch(model, u, &mut m);
        m
    };
    // ∂m/∂u_axis at every u, central differences with step h.
    let derivative = |axis: usize, h: f64| -> Vec<Vec3> {
        let shifted = |s: f64| {
            let v: Vec<[f64; 2]> = u
                .iter()
                .map(|&p| {
                    let mut p = p;
                    p[axis] += s;
                    p
                })
                .collect();
            sample(&v)
        };
        let (plus, minus) = (shifted(h), shifted(-h));
        (0..u.len())
            .map(|i| std::array::from_fn(|k| (plus[i][k] - minus[i][k]) / (2.0 * h)))
            .collect()
    };
    let richardson = |axis: usize| -> Vec<Vec3> {
        let (coarse, fine) = (derivative(axis, 1e-2), derivative(axis, 5e-3));
        (0..u.len())
            .map(|i| std::array::from_fn(|k| (4.0 * fine[i][k] - coarse[i][k]) / 3.0))
            .collect()
    };
    let (d1, d2) = (richardson(0), richardson(1));
    let m = sample(&u);
    let pdf = model.pdf_wm_batch(&m).unwrap();
    (0..u.len())
        .map(|i| {
            let (a, b) = (d1[i], d2[i]);
            let c = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            let density = 1.0 / (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            (density / pdf[i] - 1.0).abs()
        })
        .fold(0.0, f64::max)
}

/// Directions over the upper hemisphere and a few below it, plus the grid of
/// `check::against` (normal incidence, 1e-6 from it, and 1e-6 from grazing), deterministic.
fn directions(n: usize) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = (0..n)
        .map(|i| {
            let t = (i as f64 + 0.5) / n as f64;
            let theta = -0.2 + 1.75 * t;
            let phi = 2.399_963 * i as f64;
            [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]
        })
        .collect();
    for theta in [0.0, 1e-6, 1e-3, 1.56, std::f64::consts::FRAC_PI_2 - 1e-6] {
        for phi in [0.0f64, 0.7, 1.9, 4.0] {
            out.push([
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]);
        }
    }
    out
}

/// Uniform pairs in [0.001, 0.999]², deterministic (a 2-D Kronecker sequence).
fn uniforms(n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let a = (0.5 + i as f64 * 0.754_877_666_246_692_7).fract();
            let b = (0.5 + i as f64 * 0.569_840_290_998_053_3).fract();
            [0.001 + 0.998 * a, 0.001 + 0.998 * b]
        })
        .collect()
}

fn relative(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs()
    }
}

/// Which of the examples' values a comparison covers.
struct Expect {
    /// The child declares `g1`.
    g1: bool,
    /// The visible-normal pdf is the reference's times this function of wi (1 when clean;
    /// 1 + Λ(wi) for the pdf without G1).
    pdf_visible_factor: fn(&Ggx, Vec3) -> f64,
    /// The normal sampler is the reference's (false for the exponent defect, whose samples
    /// must then differ from the reference's by more than [`SAMPLE_TOLERANCE`] somewhere).
    sampler_exact: bool,
}

const CLEAN: Expect = Expect {
    g1: false,
    pdf_visible_factor: |_, _| 1.0,
    sampler_exact: true,
};

/// Starts `cmd` through the protocol and compares every capability with the reference GGX
/// (α = `ax`, `ay`) value by value: worst relative errors of D, Λ, G1 and the pdfs, worst
/// component error of the samples; every answer is a float32 number widened.
fn agrees_with_the_reference(cmd: &str, ax: f64, ay: f64, protocol: u32, expect: &Expect) {
    let model =
        ExternalModel::start(cmd, Duration::from_secs(10)).unwrap_or_else(|e| panic!("{cmd}: {e}"));
    assert_eq!(model.version(), protocol, "{cmd}: the version it chose");
    let reference = Ggx::new(ax, ay).unwrap();
    let smith = reference.as_smith().unwrap();
    let dirs = directions(20_000);
    let worst = |name: &str, points: &[Vec3], got: &[f64], want: &dyn Fn(usize) -> f64| {
        let mut w = (0.0f64, 0);
        for (i, &g) in got.iter().enumerate() {
            assert!(
                g.is_infinite() || f64::from(g as f32) == g,
                "{cmd}: {name}[{i}] = {g} is not a float32 number"
            );
            let e = relative(g, want(i));
            if !(e <= w.0) {
                w = (e, i);
            }
        }
        eprintln!(
            "{cmd}: {name} worst relative error {:.2e} at {:?}",
            w.0, points[w.1]
        );
        assert!(
            w.0 <= VALUE_TOLERANCE,
            "{cmd}: {name} at {:?}: {} vs the reference's {}",
            points[w.1],
            got[w.1],
            want(w.1)
        );
    };
    let d = model.d_batch(&dirs).unwrap();
    worst("D", &dirs, &d, &|i| reference.d(dirs[i]));
    let lambda = model.lambda_batch(&dirs).unwrap();
    worst("Λ", &dirs, &lambda, &|i| smith.lambda(dirs[i]));
    let pdf = model.pdf_wm_batch(&dirs).unwrap();
    let sampler = reference.as_sampler().unwrap();
    worst("pdf_wm", &dirs, &pdf, &|i| sampler.pdf_wm(dirs[i]));
    if expect.g1 {
        // One round trip each: a few directions against a fixed normal.
        let m = [0.1, -0.2, 0.9746794344808963];
        let few: Vec<f64> = dirs
            .iter()
            .step_by(500)
            .map(|&w| Smith::g1(&model, w, m))
            .collect();
        let ws: Vec<Vec3> = dirs.iter().step_by(500).copied().collect();
        worst("G1", &ws, &few, &|i| smith.g1(ws[i], m));
    }

    // Samples for the same u as the reference's.
    let u = uniforms(4096);
    let mut got = vec![[0.0; 3]; u.len()];
    NormalSampler::sample_wm_batch(&model, &u, &mut got);
    let sample_error = |got: &[Vec3], want: &dyn Fn(usize) -> Vec3| {
        (0..got.len())
            .map(|i| {
                let w = want(i);
                (0..3).map(|k| (got[i][k] - w[k]).abs()).fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    };
    let e = sample_error(&got, &|i| sampler.sample_wm(u[i]));
    eprintln!("{cmd}: sample_wm worst component error {e:.2e}");
    let jacobian = jacobian_error(&model);
    eprintln!("{cmd}: the sampler's density against pdf_wm: worst relative {jacobian:.2e}");
    if expect.sampler_exact {
        assert!(e <= SAMPLE_TOLERANCE, "{cmd}: sample_wm off by {e:e}");
        assert!(
            jacobian <= JACOBIAN_CLEAN,
            "{cmd}: density off by {jacobian:e}"
        );
    } else {
        assert!(
            e > 10.0 * SAMPLE_TOLERANCE,
            "{cmd}: the planted defect is not live ({e:e})"
        );
        assert!(
            jacobian >= JACOBIAN_DEFECT,
            "{cmd}: the defect's density is within {jacobian:e} of pdf_wm"
        );
    }

    let visible = reference.as_visible_sampler().unwrap();
    for (theta, phi) in [(1e-3, 1.0), (0.5, 0.3), (1.3, 0.3), (1.55, 2.0)] {
        let wi = [
            f64::sin(theta) * f64::cos(phi),
            f64::sin(theta) * f64::sin(phi),
            f64::cos(theta),
        ];
        let mut got = vec![[0.0; 3]; u.len()];
        model.sample_wm_visible_batch(wi, &u, &mut got);
        let e = sample_error(&got, &|i| visible.sample_wm_visible(wi, u[i]));
        eprintln!("{cmd}: sample_wm_visible at θi = {theta} worst component error {e:.2e}");
        assert!(
            e <= SAMPLE_TOLERANCE,
            "{cmd}: sample_wm_visible off by {e:e}"
        );
        // The density at upper-hemisphere directions: its cosine ⟨wi·m⟩ is computed in float
        // from float inputs, off by up to ~5 ε absolute, so the bound grows as the cosine
        // vanishes at the terminator (measured: 1.4e-5 relative where wi·m = 0.02).
        let ms: Vec<Vec3> = dirs.iter().filter(|m| m[2] > 0.0).copied().collect();
        let mut pdf = vec![0.0; ms.len()];
        model.pdf_wm_visible_batch(wi, &ms, &mut pdf);
        let factor = (expect.pdf_visible_factor)(&reference, wi);
        for (i, &m) in ms.iter().enumerate() {
            let want = factor * visible.pdf_wm_visible(wi, m);
            let cosine = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2];
            if want == 0.0 || cosine <= 20.0 * F32_EPS {
                // Back-facing (0 both), or within the float rounding of the terminator.
                assert!(
                    pdf[i] == 0.0 || cosine > -20.0 * F32_EPS,
                    "{cmd}: pdf_wm_visible({wi:?}, {m:?}) = {} behind the terminator",
                    pdf[i]
                );
                continue;
            }
            let bound = VALUE_TOLERANCE + 10.0 * F32_EPS / cosine;
            assert!(
                relative(pdf[i], want) <= bound,
                "{cmd}: pdf_wm_visible({wi:?}, {m:?}) = {} vs {want} (bound {bound:e})",
                pdf[i]
            );
        }
    }
    assert!(model.first_error().is_none(), "{:?}", model.first_error());
    model.shutdown();
}

/// A child spoken to line by line, for what `ExternalModel` does not show (the raw describe
/// answer, error answers). Every read waits at most 10 s.
struct Raw {
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<String>,
}

impl Raw {
    fn start(cmd: &str) -> Raw {
        let mut child = Command::new("sh")
            .args(["-c", cmd])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Raw {
            child,
            stdin,
            lines,
        }
    }

    fn ask(&mut self, line: impl AsRef<[u8]>) -> Value {
        let line = line.as_ref();
        self.stdin.write_all(line).unwrap();
        self.stdin.write_all(b"\n").unwrap();
        self.stdin.flush().unwrap();
        let answer = self.lines.recv_timeout(Duration::from_secs(10));
        let answer = answer
            .unwrap_or_else(|e| panic!("no answer to {} ({e})", String::from_utf8_lossy(line)));
        serde_json::from_str(&answer).unwrap_or_else(|e| panic!("{answer}: {e}"))
    }

    /// Sends shutdown and waits for the child to exit (at most 10 s): its status.
    fn shutdown(mut self) -> std::process::ExitStatus {
        writeln!(self.stdin, r#"{{"v":2,"id":99,"op":"shutdown"}}"#).unwrap();
        drop(self.stdin);
        let t = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            if t.elapsed() > Duration::from_secs(10) {
                let _ = self.child.kill();
                panic!("the child did not exit after shutdown");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

const DESCRIBE: &str = r#"{"v":1,"id":0,"op":"describe","versions":[1,2]}"#;

/// The describe answer of `cmd` declares float32 precision, version 2 and `capabilities`.
fn describes_itself_as_f32(cmd: &str, name: &str, capabilities: &[&str]) {
    let mut raw = Raw::start(cmd);
    let d = raw.ask(DESCRIBE);
    assert_eq!(d["id"], 0, "{d}");
    assert_eq!(d["protocol"], 2, "{d}");
    assert_eq!(d["precision"], "f32", "{d}");
    assert_eq!(d["name"], name, "{d}");
    assert_eq!(d["parameters"]["family"], "ggx", "{d}");
    assert_eq!(d["capabilities"], serde_json::json!(capabilities), "{d}");
    assert!(raw.shutdown().success());
}

#[test]
#[cfg_attr(
    not(has_gxx),
    ignore = "g++ is not installed (apt-get install g++; .ci/run installs it)"
)]
fn the_cpp_example_agrees_with_the_reference_to_float32_accuracy() {
    let caps = [
        "d",
        "lambda",
        "g1",
        "sample_wm",
        "pdf_wm",
        "sample_wm_visible",
        "pdf_wm_visible",
    ];
    describes_itself_as_f32(&cpp_command(""), "ggx_float.cpp", &caps);
    let with_g1 = Expect { g1: true, ..CLEAN };
    for (ax, ay, protocol) in [(0.3, 0.3, 2), (0.1, 0.4, 2), (0.1, 0.4, 1)] {
        let args = format!("--alpha-x {ax} --alpha-y {ay} --protocol {protocol}");
        agrees_with_the_reference(&cpp_command(&args), ax, ay, protocol, &with_g1);
    }
    // The planted defect is live: the visible pdf is the reference's times 1 + Λ(wi) (its
    // integral), everything else unchanged.
    let defect = Expect {
        pdf_visible_factor: |g, wi| 1.0 + g.as_smith().unwrap().lambda(wi),
        ..with_g1
    };
    let cmd = cpp_command("--defect vndf_pdf_without_g1");
    agrees_with_the_reference(&cmd, 0.3, 0.3, 2, &defect);
}

#[test]
#[cfg_attr(
    not(has_numpy),
    ignore = "numpy is not installed (python3 -m pip install numpy)"
)]
fn the_numpy_f32_example_agrees_with_the_reference_to_float32_accuracy() {
    require_numpy();
    let caps = [
        "d",
        "lambda",
        "sample_wm",
        "pdf_wm",
        "sample_wm_visible",
        "pdf_wm_visible",
    ];
    let file = "ggx_f32_numpy.py";
    describes_itself_as_f32(&example(file, ""), file, &caps);
    for (ax, ay, protocol) in [(0.3, 0.3, 2), (0.1, 0.4, 2), (0.1, 0.4, 1)] {
        let args = format!("--alpha-x {ax} --alpha-y {ay} --protocol {protocol}");
        agrees_with_the_reference(&example(file, &args), ax, ay, protocol, &CLEAN);
    }
    // The planted defect is live: the normal sampler's samples move, its pdf does not.
    let defect = Expect {
        sampler_exact: false,
        ..CLEAN
    };
    agrees_with_the_reference(&example(file, "--defect exponent"), 0.3, 0.3, 2, &defect);
}

/// The helper answers each malformed request with an error naming what is wrong (and the
/// request's id where it could read one), and keeps serving; `describe` without `versions`
/// chooses version 1, in which base64 is refused.
#[test]
#[cfg_attr(
    not(has_gxx),
    ignore = "g++ is not installed (apt-get install g++; .ci/run installs it)"
)]
fn the_cpp_helper_answers_malformed_requests_with_clear_errors() {
    let mut raw = Raw::start(&cpp_command(""));
    assert_eq!(raw.ask(DESCRIBE)["protocol"], 2);
    let big = format!(
        r#"{{"v":2,"id":12,"op":"d","n":1,"m":{}1{}}}"#,
        "[".repeat(100),
        "]".repeat(100)
    );
    let cases: [(&[u8], Value, &str); 16] = [
        (b"nope", Value::Null, "invalid JSON at byte 0"),
        (
            br#"{"v":2,"id":1,"op":"d","n":1,"m":"AAAA"}"#,
            1.into(),
            "3 bytes of base64-decoded data",
        ),
        (
            br#"{"v":2,"id":2,"op":"d","n":1,"m":"AAA"}"#,
            2.into(),
            "not a multiple of 4",
        ),
        (
            br#"{"v":2,"id":3,"op":"d","n":1,"m":"AAAAAAA*AAA="}"#,
            3.into(),
            "character '*'",
        ),
        (
            br#"{"v":2,"id":4,"op":"d","n":2,"m":[[0,0,1]]}"#,
            4.into(),
            "\"n\" is 2 but the arrays hold 1",
        ),
        (
            br#"{"v":2,"id":5,"op":"d","m":[[0,0,1]]}"#,
            5.into(),
            "carries \"n\"",
        ),
        (
            br#"{"v":2,"id":6,"op":"pdf_wm_visible","n":1,"wi":[[0,0,1]],"m":[[0,0,1],[0,0,1]]}"#,
            6.into(),
            "\"wi\" has 1 items but \"m\" has 2",
        ),
        (
            br#"{"v":2,"id":7,"op":"d","n":1,"m":[[0,0]]}"#,
            7.into(),
            "\"m\" item 0: not an array of 3 numbers",
        ),
        (
            br#"{"v":2,"id":8,"op":"g2","n":0,"wo":[],"wi":[],"m":[]}"#,
            8.into(),
            "unknown op \"g2\"",
        ),
        (
            br#"{"v":2,"id":9,"op":"d","n":1,"m":[[0,0,1]],"m":[[0,0,1]]}"#,
            Value::Null,
            "duplicate key \"m\"",
        ),
        (
            br#"{"v":1,"id":10,"op":"d","n":1,"m":[[0,0,1]]}"#,
            10.into(),
            "describe chose version 2",
        ),
        (
            br#"{"v":2,"id":11,"op":"d","n":1,"m":[[0,0,01]]}"#,
            Value::Null,
            "leading zero",
        ),
        (big.as_bytes(), Value::Null, "nested deeper than 64"),
        (
            b"{\"v\":2,\"id\":13,\"op\":\"d\xff\"}",
            Value::Null,
            "invalid UTF-8",
        ),
        (
            br#"{"v":2,"id":14,"op":"\ud800"}"#,
            Value::Null,
            "high surrogate",
        ),
        (
            br#"{"v":2,"id":15,"op":"d","n":1}"#,
            15.into(),
            "no \"m\" array",
        ),
    ];
    for (line, id, want) in cases {
        let a = raw.ask(line);
        let line = String::from_utf8_lossy(line);
        let e = a["error"].as_str().unwrap_or_else(|| panic!("{line}: {a}"));
        assert!(e.contains(want), "{line}: {e:?} does not say {want:?}");
        assert_eq!(a["id"], id, "{line}: {a}");
    }
    // Still serving, correctly: D(n) = 1/(π α²) in float.
    let a = raw.ask(r#"{"v":2,"id":20,"op":"d","n":1,"m":[[0,0,1]]}"#);
    let bytes = base64_f64(a["values"].as_str().unwrap());
    let want = 1.0 / (std::f64::consts::PI * 0.09);
    assert!(relative(bytes[0], want) < VALUE_TOLERANCE, "{a}");
    assert!(raw.shutdown().success());

    // Version 1 where describe offers nothing: base64 is refused, JSON arrays answer, ∞ is the
    // bare token.
    let mut raw = Raw::start(&cpp_command(""));
    assert_eq!(raw.ask(r#"{"v":1,"id":0,"op":"describe"}"#)["protocol"], 1);
    let a = raw.ask(r#"{"v":1,"id":1,"op":"d","m":"AAAAAAAA8D8="}"#);
    assert!(a["error"].as_str().unwrap().contains("version 2"), "{a}");
    writeln!(
        raw.stdin,
        r#"{{"v":1,"id":2,"op":"lambda","w":[[1,0,0],[0,0,1]]}}"#
    )
    .unwrap();
    raw.stdin.flush().unwrap();
    let line = raw.lines.recv_timeout(Duration::from_secs(10)).unwrap();
    assert_eq!(line, r#"{"id":2,"values":[Infinity,0]}"#);
    assert!(raw.shutdown().success());

    // Bad options: exit 2 with a message naming the option.
    let out = Command::new(cpp_example())
        .args(["--alpha", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--alpha is \"0\""), "{stderr}");
}

/// Decodes base64 of little-endian f64 (the test's own decoder: the standard alphabet, padded).
fn base64_f64(text: &str) -> Vec<f64> {
    use base64::Engine;
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(text)
        .unwrap();
    bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The ci audits at the declared float32 precision.
// ---------------------------------------------------------------------------------------------

const AGAINST: &str = r#"{"family":"ggx","alpha":0.3}"#;

/// `mfh audit-external --cmd <cmd> --profile ci --against GGX 0.3`: (exit code, the checks
/// whose records failed or erred, the report), printing the wall time and record counts.
fn audit(cmd: &str, label: &str) -> (i32, Vec<String>, Value) {
    audit_against(cmd, label, AGAINST)
}

/// [`audit`] against the reference spec `against`.
fn audit_against(cmd: &str, label: &str, against: &str) -> (i32, Vec<String>, Value) {
    let out = std::env::temp_dir().join(format!("mfh-f32-{label}-{}", std::process::id()));
    let args = [
        "audit-external",
        "--cmd",
        cmd,
        "--profile",
        "ci",
        "--against",
        against,
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    let t = Instant::now();
    let (code, stdout, stderr) = run(&args);
    let report: Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{label}: no report ({e}): {stdout}{stderr}"));
    let records = report["records"].as_array().unwrap();
    let failing: Vec<String> = records
        .iter()
        .filter(|r| matches!(r["verdict"].as_str(), Some("fail") | Some("error")))
        .map(|r| r["check"].as_str().unwrap_or("").to_string())
        .collect();
    eprintln!(
        "{label}: exit {code} in {:.1} s, {} records, failing {failing:?}",
        t.elapsed().as_secs_f64(),
        records.len()
    );
    let _ = std::fs::remove_dir_all(&out);
    (code, failing, report)
}

fn checks(report: &Value) -> Vec<&str> {
    report["records"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|r| r["check"].as_str())
        .collect()
}

/// The C++ float32 GGX passes the ci audit with `"precision":"f32"`: D, Λ, G1, both samplers
/// and the values against the reference (the target: within 1 min on 2 cores).
#[test]
#[cfg_attr(
    not(has_gxx),
    ignore = "g++ is not installed (apt-get install g++; .ci/run installs it)"
)]
fn the_cpp_example_passes_the_ci_audit_at_f32() {
    let (code, failing, report) = audit(&cpp_command(""), "cpp");
    assert_eq!(code, 0, "failing: {failing:?}");
    let run = checks(&report);
    for want in [
        "normalization.projected_area",
        "smith.white_furnace",
        "sampling.chi2",
        "sampling.pdf_jacobian",
        "sampling.chi2_visible",
        "sampling.pdf_visible_normalization",
        "against.reference",
    ] {
        assert!(run.contains(&want), "{want} not run: {run:?}");
    }
}

/// The visible-normal pdf without G1 integrates to 1 + Λ(wi) (1.0067 at θi = 0.5, 1.24 at
/// 1.3 for α = 0.3): `sampling.pdf_visible_normalization` fails; nothing outside visible
/// sampling does.
#[test]
#[cfg_attr(
    not(has_gxx),
    ignore = "g++ is not installed (apt-get install g++; .ci/run installs it)"
)]
fn the_cpp_vndf_pdf_without_g1_fails_the_visible_pdf_normalization() {
    let cmd = cpp_command("--defect vndf_pdf_without_g1");
    let (code, failing, _) = audit(&cmd, "cpp-defect");
    assert_eq!(code, 1);
    assert!(
        failing
            .iter()
            .any(|c| c == "sampling.pdf_visible_normalization"),
        "failing: {failing:?}"
    );
    for c in &failing {
        assert!(
            c.contains("visible"),
            "{c} fails, but only the visible pdf is wrong"
        );
    }
}

/// The float32 numpy GGX passes the ci audit with `"precision":"f32"` (the target:
/// within 2 min on 2 cores).
#[test]
#[cfg_attr(
    not(has_numpy),
    ignore = "numpy is not installed (python3 -m pip install numpy)"
)]
fn the_numpy_f32_example_passes_the_ci_audit_at_f32() {
    require_numpy();
    let (code, failing, report) = audit(&example("ggx_f32_numpy.py", ""), "numpy");
    assert_eq!(code, 0, "failing: {failing:?}");
    let run = checks(&report);
    for want in [
        "sampling.pdf_jacobian",
        "sampling.chi2_visible",
        "against.reference",
    ] {
        assert!(run.contains(&want), "{want} not run: {run:?}");
    }
}

/// The slope-radius exponent 0.5 · 1.001 moves the sampled density ~0.1 % away from pdf_wm:
/// `sampling.pdf_jacobian` (pdf_wm against the density of the map u ↦ m) fails; the visible
/// sampler and the values are right, so nothing else outside the normal sampler's checks does.
#[test]
#[cfg_attr(
    not(has_numpy),
    ignore = "numpy is not installed (python3 -m pip install numpy)"
)]
fn the_numpy_exponent_defect_fails_the_jacobian_check() {
    require_numpy();
    let cmd = example("ggx_f32_numpy.py", "--defect exponent");
    let (code, failing, _) = audit(&cmd, "numpy-defect");
    assert_eq!(code, 1);
    assert!(
        failing.iter().any(|c| c == "sampling.pdf_jacobian"),
        "failing: {failing:?}"
    );
    for c in &failing {
        assert!(
            c.starts_with("sampling.") && !c.contains("visible"),
            "{c} fails, but only the normal sampler is wrong"
        );
    }
}

const DIELECTRIC: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;

/// The float32 numpy rough dielectric (pbrt-v4's algebra) passes the ci audit with
/// `"precision":"f32"`: every BSDF check, judged at its float32 row, against the reference.
#[test]
#[cfg_attr(
    not(has_numpy),
    ignore = "numpy is not installed (python3 -m pip install numpy)"
)]
fn the_numpy_f32_dielectric_passes_the_ci_audit_at_f32() {
    require_numpy();
    let cmd = example("dielectric_f32_numpy.py", "");
    let (code, failing, report) = audit_against(&cmd, "numpy-dielectric", DIELECTRIC);
    assert_eq!(code, 0, "failing: {failing:?}");
    let run = checks(&report);
    for want in [
        "bsdf.chi2",
        "bsdf.sample_consistency",
        "bsdf.albedo",
        "bsdf.reciprocity",
        "bsdf.against",
        "bsdf.stability",
    ] {
        assert!(run.contains(&want), "{want} not run: {run:?}");
    }
    for r in report["records"].as_array().unwrap() {
        assert_eq!(r["precision"], "f32", "{r}");
    }
}

/// The refraction Jacobian with |wi·m| for |wo·m|, in pdf and sample alike: the sampled
/// directions no longer follow pdf, and `bsdf.chi2` fails.
#[test]
#[cfg_attr(
    not(has_numpy),
    ignore = "numpy is not installed (python3 -m pip install numpy)"
)]
fn the_numpy_f32_dielectric_jacobian_defect_fails_the_chi_square() {
    require_numpy();
    let cmd = example("dielectric_f32_numpy.py", "--defect jacobian_wi");
    let (code, failing, _) = audit_against(&cmd, "numpy-dielectric-defect", DIELECTRIC);
    assert_eq!(code, 1);
    assert!(
        failing.iter().any(|c| c == "bsdf.chi2"),
        "failing: {failing:?}"
    );
}

/// pbrt-v4's tangent frame (`--defect frame_switch`: T1 = x̂ wherever w_h,z ≥ 0.99999, not
/// orthogonal to w_h there) fails `sampling.visible_jacobian` at seeds 7, 8 and 9 with a region
/// of θi near the normal (α tan θi < 4.5e-3: θi < 0.015 rad at α 0.3); the correct example
/// passes it at the same seeds. Only that check runs, with the seed the whole ci audit gives it
/// (the rest of the audit is the test above's).
#[test]
#[cfg_attr(
    not(has_gxx),
    ignore = "g++ is not installed (apt-get install g++; .ci/run installs it)"
)]
fn the_cpp_frame_switch_fails_the_visible_jacobian_near_the_normal() {
    use mfh_harness::check::RunContext;
    use mfh_harness::external::{plan, ExternalAudit};
    use mfh_harness::run::check_seed;
    for (args, defect) in [("--defect frame_switch", true), ("", false)] {
        let cmd = cpp_command(args);
        let model = ExternalModel::start(&cmd, Duration::from_secs(10))
            .unwrap_or_else(|e| panic!("{cmd}: {e}"));
        for seed in [7, 8, 9] {
            let request = ExternalAudit {
                command: cmd.clone(),
                profile: mfh_harness::Profile::Ci,
                seed,
                against: None,
                timeout: Duration::from_secs(10),
                out: None,
                control: Default::default(),
            };
            let label = serde_json::json!({"name": cmd});
            let (plan, _) = plan(&model, &request, "cpp", &label);
            let named: Vec<_> = plan
                .iter()
                .filter(|p| p.check == "sampling.visible_jacobian")
                .collect();
            assert_eq!(named.len(), 1, "{cmd}");
            let r = (named[0].run)(&RunContext {
                seed: check_seed(seed, named[0]),
            });
            let region = r.region.as_ref().map(|g| g.text.as_str());
            eprintln!(
                "{cmd} seed {seed}: {:?} {:?} {region:?}",
                r.verdict, r.measured
            );
            if defect {
                assert!(r.verdict.is_failure(), "{cmd} seed {seed}: {:?}", r.verdict);
                let g = r.region.expect("a failing sweep has a region");
                assert!(g.to > 0.008 && g.to < 0.0155 && g.from < 0.01, "{}", g.text);
            } else {
                assert!(
                    !r.verdict.is_failure(),
                    "{cmd} seed {seed}: {:?}",
                    r.verdict
                );
            }
        }
    }
}
