//! End to end: `mfh audit --out DIR` writes a self-contained `report.html` ("The
//! HTML report") that headless Chromium opens without console or resource errors, every image
//! with a non-zero natural size; a screenshot goes to `target/tmp/mfh-html-report/`. Without
//! Chromium the browser test is ignored (listed as such), unless `CI=true` (then it must run).
//! Also the bad-input contract: an unwritable `--out` or a report that cannot be written whole
//! exits 2 with a clear message, and report.json is written first.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn mfh(args: &[&str]) -> (i32, String, String) {
    mfh_harness::cli::run_captured(args)
}

/// The test's output folder (kept after the run: the screenshot is for people to look at).
fn out_folder() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mfh-html-report");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A small scene: a GGX material that masks and samples (Λ plots, chi-square heat maps, KS
/// marginals) and an STD one (γ → ∞ limits, document 001 errata and claims).
const SCENE: &str = r#"{
  "name": "html report test",
  "materials": [
    {"name": "floor", "model": {"family": "ggx", "alpha": 0.3},
     "masking": "height_correlated", "sampling": "normals"},
    {"name": "cloth", "model": {"family": "std", "gamma": 3.0, "alpha": 0.3},
     "masking": "uncorrelated"}
  ],
  "incidence": {"theta_max": 1.5}
}"#;

/// A cost.json as `mfh cost` writes it, for the accuracy-versus-time section.
const COST: &str = r#"{"quantities":[{"name":"STD Λ","routes":[
  {"route":"stable","seconds_per_eval":4e-8,"max_error":2e-16},
  {"route":"2f1","seconds_per_eval":9e-7,"max_error":4e-14},
  {"route":"table1","seconds_per_eval":2e-8,"max_error":3e-3}]}]}"#;

/// The Chromium binary, if one is installed.
fn chromium() -> Option<PathBuf> {
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .find_map(|name| {
            let ok = Command::new(name)
                .arg("--version")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .map(|s| s.success())
                .unwrap_or(false);
            ok.then(|| PathBuf::from(name))
        })
}

/// Runs headless Chromium with `args` (at most `limit`; killed past it); returns stdout and
/// stderr.
fn headless(browser: &Path, profile: &Path, args: &[String], limit: Duration) -> (String, String) {
    let out_path = profile.with_extension("stdout");
    let err_path = profile.with_extension("stderr");
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--hide-scrollbars",
            &format!("--user-data-dir={}", profile.display()),
        ])
        .args(args)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within {limit:?}: {args:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    (
        std::fs::read_to_string(out_path).unwrap_or_default(),
        std::fs::read_to_string(err_path).unwrap_or_default(),
    )
}

/// The probe injected into a copy of the report: it records every script error, console error
/// and failed resource load from the start, and after load writes, into an element with id
/// `mfh-probe`, one JSON object: the images, those with a zero natural size, and the errors.
const PROBE_HEAD: &str = "<script>window.__mfh={errors:[]};\
window.addEventListener('error',function(e){window.__mfh.errors.push(e.message||\
('resource failed: '+((e.target&&(e.target.src||e.target.href))||'?')).slice(0,200));},true);\
(function(){var c=console.error;console.error=function(){window.__mfh.errors.push('console.error: '+\
Array.prototype.join.call(arguments,' '));c.apply(console,arguments);};})();</script>";
const PROBE_END: &str = "<script>window.addEventListener('load',function(){\
var imgs=Array.prototype.slice.call(document.images);var zero=imgs.filter(function(i){\
return !(i.complete&&i.naturalWidth>0&&i.naturalHeight>0);}).map(function(i){return i.alt;});\
var p=document.createElement('pre');p.id='mfh-probe';p.textContent=JSON.stringify({images:imgs.length,\
zero:zero,errors:window.__mfh.errors,title:document.title});document.body.appendChild(p);});</script>";

/// Runs the audit of [`SCENE`] (with [`COST`]) into `out_folder()/<name>/out`; returns that
/// folder, report.html's path and its text.
fn audit_into(name: &str) -> (PathBuf, PathBuf, String) {
    let dir = out_folder().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.json");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("cost.json"), COST).unwrap();
    let (code, stdout, stderr) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let html_path = out.join("report.html");
    assert!(
        stdout.contains(&format!("wrote {}", html_path.display())),
        "{stdout}"
    );
    let html = std::fs::read_to_string(&html_path).unwrap();
    (out, html_path, html)
}

/// The `alt` texts of report.html's images.
fn image_alts(html: &str) -> Vec<&str> {
    html.split("<img ")
        .skip(1)
        .map(|rest| {
            let a = rest.find("alt=\"").map_or(0, |i| i + 5);
            &rest[a..a + rest[a..].find('"').unwrap_or(0)]
        })
        .collect()
}

#[test]
fn the_audit_writes_a_self_contained_report_html() {
    let (out, _, html) = audit_into("content");
    // Self-contained: no external resources, no scripts.
    for forbidden in ["http://", "https://", "<script", "src=\"chi2"] {
        assert!(
            !html.contains(forbidden),
            "report.html contains {forbidden}"
        );
    }
    for section in [
        "PASS",
        "mfh audit --profile quick --seed 5",
        "id=failures",
        "Λ of ggx alpha=0.3 against the oracle",
        "G1 = 1/(1 + Λ)",
        "id=limits",
        "id=stability",
        "id=errata",
        "001-",
        "id=claims",
        "claims.std_includes_ggx",
        "BEGIN accuracy-versus-time",
        "STD Λ",
        "id=checks",
    ] {
        assert!(html.contains(section), "report.html lacks {section:?}");
    }
    // Written for people: no "1 records", the heat maps' densities explained, no Rust
    // `Debug` forms.
    assert!(!html.contains(">1 records") && !html.contains("(1 records"));
    assert!(html.contains("counts / (N · cell solid angle)"));
    for debug in ["Some(", "None,", "PValue {"] {
        assert!(!html.contains(debug), "report.html contains {debug}");
    }
    // A size a browser opens at once (report.html of the default scene's quick audit
    // was 19 MB; plots now only for failures, expected failures and one per check family,
    // decimated paths, heat maps as embedded bitmaps): the bound 3 MB, and no image over
    // 200 kB of data URI.
    assert!(
        html.len() < 3_000_000,
        "report.html is {} bytes, over the 3 MB bound",
        html.len()
    );
    let largest_image = html
        .split("src=\"data:")
        .skip(1)
        .map(|rest| rest.find('"').unwrap_or(rest.len()))
        .max()
        .unwrap_or(0);
    assert!(
        largest_image < 200_000,
        "an embedded image of {largest_image} bytes"
    );
    let alts = image_alts(&html);
    let images = alts.len();
    eprintln!("images: {alts:#?}");
    // Plots are drawn for failures, expected failures and the first passing record of each
    // check family (the rest are table rows with their error): Λ and G1 of the first material
    // (2); GGX's 3 chi-square maps and its first KS plot (1); the 2 γ → ∞ limits (D and Λ);
    // 1 Pareto plot. Every route-stress record passes, so none is drawn.
    let expected = 2 + 3 + 1 + 2 + 1;
    assert_eq!(images, expected, "images in report.html");
    // report.json lists the chi-square artefacts (and holds no tables); they exist.
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let chi2 = report["records"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["check"] == "sampling.chi2")
        .expect("a chi-square record");
    assert!(chi2.get("data").is_none(), "tables stay out of report.json");
    let artefacts: Vec<&str> = chi2["artefacts"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .collect();
    assert_eq!(artefacts.len(), 5, "{artefacts:?}");
    let folder = out
        .join("chi2")
        .join("alpha_0.3_family_ggx_resolution_16_samples_200000");
    for a in &artefacts {
        assert!(Path::new(a).starts_with(&folder), "{a}");
        assert!(Path::new(a).is_file(), "{a}");
    }
    // The heat maps: densities, axes in radians (as every other plot), ticks at π/8 and π/2.
    let map = std::fs::read_to_string(folder.join("chi2_observed.svg")).unwrap();
    for text in [
        "observed density",
        "density (sr⁻¹)",
        "θ (radians)",
        "φ (radians)",
        "3π/2",
    ] {
        assert!(map.contains(text), "chi2_observed.svg lacks {text:?}");
    }
    assert!(!map.contains("degrees"));
}

/// Headless Chromium opens report.html without console or resource errors, every image with a
/// non-zero natural size; a screenshot goes to `target/tmp/mfh-html-report/`. Ignored where
/// Chromium is absent, except under CI=true (the build script's `has_chromium`), where .ci/run
/// installs it and its absence fails the test.
#[test]
#[cfg_attr(not(has_chromium), ignore = "no chromium (apt-get install chromium)")]
fn chromium_renders_the_report_html() {
    let browser = chromium().expect(
        "no chromium (CI=true, or it was removed since the build): .ci/run installs it \
         (apt-get install chromium)",
    );
    let (_, html_path, html) = audit_into("browser");
    let images = image_alts(&html).len();
    let dir = out_folder();
    // 1. The probe: load a copy with the probe scripts, dump the DOM after load.
    let probe_path = dir.join("report-probe.html");
    let probed = html
        .replacen("<head>", &format!("<head>{PROBE_HEAD}"), 1)
        .replacen("</body>", &format!("{PROBE_END}</body>"), 1);
    std::fs::write(&probe_path, probed).unwrap();
    let url = format!("file://{}", probe_path.display());
    let (dom, log) = headless(
        &browser,
        &dir.join("profile-probe"),
        &[
            "--virtual-time-budget=20000".to_string(),
            "--dump-dom".to_string(),
            url,
        ],
        Duration::from_secs(240),
    );
    let start = dom
        .find("<pre id=\"mfh-probe\">")
        .unwrap_or_else(|| panic!("no probe result in the DOM; chromium said:\n{log}"));
    let text = &dom[start + "<pre id=\"mfh-probe\">".len()..];
    let text = &text[..text.find("</pre>").unwrap()];
    let probe: Value = serde_json::from_str(
        &text
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&amp;", "&"),
    )
    .unwrap();
    eprintln!("probe: {probe}");
    assert_eq!(probe["images"].as_u64(), Some(images as u64), "{probe}");
    assert_eq!(probe["zero"], serde_json::json!([]), "images without size");
    assert_eq!(probe["errors"], serde_json::json!([]), "page errors");
    assert!(probe["title"]
        .as_str()
        .unwrap()
        .contains("html report test"));
    // 2. The report itself, unmodified: no console errors in Chromium's log, and a screenshot.
    let shot = dir.join("report-screenshot.png");
    let _ = std::fs::remove_file(&shot);
    let (_, log) = headless(
        &browser,
        &dir.join("profile-shot"),
        &[
            "--enable-logging=stderr".to_string(),
            "--v=0".to_string(),
            "--window-size=1360,2600".to_string(),
            "--virtual-time-budget=20000".to_string(),
            format!("--screenshot={}", shot.display()),
            format!("file://{}", html_path.display()),
        ],
        Duration::from_secs(240),
    );
    let console: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("CONSOLE") || l.contains("Uncaught"))
        .collect();
    assert!(console.is_empty(), "console output: {console:?}");
    let png = std::fs::read(&shot).unwrap_or_else(|e| panic!("no screenshot ({e}):\n{log}"));
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(
        png.len() > 20_000,
        "a blank screenshot? {} bytes",
        png.len()
    );
    eprintln!("screenshot: {}", shot.display());
}

#[test]
fn an_unwritable_out_exits_2_and_a_failing_sink_keeps_report_json() {
    let dir = out_folder().join("bad-out");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"name": "tiny", "materials": [{"name": "m", "model": {"family": "ggx",
            "alpha": 0.3}}], "incidence": {"theta_max": 1.4}}"#,
    )
    .unwrap();
    // --out under a regular file: no folder can be made there (root included).
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let under = file.join("out");
    let (code, stdout, stderr) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        under.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stdout}{stderr}");
    assert!(stderr.contains(under.to_str().unwrap()), "{stderr}");
    // report.html cannot be written (a folder is in its way): exit 2, the message names it,
    // and report.json and junit.xml were written before.
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("report.html")).unwrap();
    let (code, stdout, stderr) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stdout}{stderr}");
    assert!(stderr.contains("report.html"), "{stderr}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(report["records"].as_array().unwrap().len() > 5);
    assert!(out.join("junit.xml").is_file());
}

/// A number as report.html's tables write it (the one short form of every sink).
fn fmt_num(x: f64) -> String {
    mfh_harness::report::text::num(x)
}

/// The BSDF section of a dielectric's audit — both hemispheres' observed / expected /
/// residual maps at each of the five incidences, the albedo plot, and the albedo, consistency
/// and reciprocity tables holding the records' numbers (read back from report.json).
#[test]
fn the_report_html_has_a_bsdf_section() {
    let dir = out_folder().join("bsdf");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"name": "bsdf section", "materials": [{"name": "glass", "bsdf": {"type":
            "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}}]}"#,
    )
    .unwrap();
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    let (code, stdout, stderr) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<a href=#bsdf>BSDFs</a>"));
    let start = html.find("<h2 id=bsdf>").expect("a BSDF section");
    let section = &html[start..start + html[start..].find("<h2 id=limits>").unwrap()];
    assert!(
        section.contains("<h3 id=bsdf-0>dielectric eta=1.5"),
        "{}",
        &section[..400]
    );
    // The BSDF's records are in its section, not under the materials.
    let materials = &html[html.find("<h2 id=materials>").unwrap()..start];
    assert!(!materials.contains("bsdf."), "{materials}");
    // Maps: reflection and transmission × observed, expected, residual at every incidence.
    let alts = image_alts(section);
    for incidence in [
        "normal",
        "oblique",
        "grazing",
        "inside",
        "total internal reflection",
    ] {
        for side in ["reflection", "transmission"] {
            for map in ["observed", "expected", "difference"] {
                let alt = format!("bsdf.chi2 {incidence} {side} chi2_{map}.svg");
                assert!(alts.contains(&alt.as_str()), "no {alt} in {alts:?}");
            }
        }
    }
    assert!(alts.contains(&"bsdf.albedo against incidence"), "{alts:?}");
    assert_eq!(alts.len(), 5 * 2 * 3 + 1, "{alts:?}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let records = report["records"].as_array().unwrap();
    let of = |check: &str| -> Vec<&Value> {
        records
            .iter()
            .filter(|r| r["check"] == check && r["case"]["variant"].is_null())
            .collect()
    };
    let num = |v: &Value| fmt_num(v.as_f64().unwrap_or_else(|| panic!("not a number: {v}")));
    let has = |text: String| assert!(section.contains(&text), "the section lacks {text:?}");
    // Albedo: quadrature ± bound, mean weight ± standard error, and both parts.
    let albedo = of("bsdf.albedo");
    assert_eq!(albedo.len(), 5);
    for r in &albedo {
        has(format!(
            "{} ± {}",
            num(&r["oracle"]["value"]),
            num(&r["oracle"]["uncertainty"])
        ));
        has(format!(
            "{} ± {}",
            num(&r["value"]),
            num(&r["case"]["standard_error"])
        ));
        for part in ["reflection", "transmission"] {
            let p = &r["case"][part];
            has(format!(
                "{} ± {} / {} ± {}",
                num(&p["albedo"]),
                num(&p["error_bound"]),
                num(&p["mean_weight"]),
                num(&p["standard_error"])
            ));
        }
        // The parts add up to the total (the record's numbers, not the sink's).
        let sum = r["case"]["reflection"]["mean_weight"].as_f64().unwrap()
            + r["case"]["transmission"]["mean_weight"].as_f64().unwrap();
        assert!((sum - r["value"].as_f64().unwrap()).abs() < 1e-12, "{r}");
    }
    // Consistency: the pdf and weight errors apart, the failure rate against 1 − ∫ pdf.
    for r in of("bsdf.sample_consistency") {
        has(format!(
            "<td class=num>{}</td><td class=num>{}</td>",
            num(&r["case"]["worst_pdf_error"]),
            num(&r["case"]["worst_weight_error"])
        ));
    }
    let rates = of("bsdf.failure_rate");
    assert_eq!(rates.len(), 5);
    for r in rates {
        has(format!(
            "{} ({} of {})",
            num(&r["value"]),
            r["case"]["failed_samples"],
            r["case"]["samples"]
        ));
        has(format!(
            "{} ± {}",
            num(&r["oracle"]["value"]),
            num(&r["oracle"]["uncertainty"])
        ));
    }
    // Reciprocity: the worst relative error, where, the tolerance and the verdict.
    let rec = &of("bsdf.reciprocity")[0];
    has(format!(
        "{} direction pairs, transport radiance, η = 1.5",
        rec["case"]["pairs"]
    ));
    has(format!(
        "<td class=num>{}</td><td>wi = (",
        num(&rec["value"])
    ));
    has(format!(
        "f(wi, wo) = {}",
        num(&rec["case"]["worst"]["f_wi_wo"])
    ));
    has(format!(
        "{} = {}</td><td>pass</td>",
        rec["tolerance"]["name"].as_str().unwrap(),
        num(&rec["tolerance"]["value"])
    ));
    // The stressed variants' stability records are listed in the section.
    assert!(section.contains("stressed variants"));
}
