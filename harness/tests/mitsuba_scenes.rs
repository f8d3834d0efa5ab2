//! The Mitsuba 3 example scenes under `examples/scenes/` plan what they should: which
//! materials (NDF, masking, sampling), which checks for each, which plugins are not audited
//! and why; malformed XML is an error at file:line:column.

use mfh_harness::check::Profile;
use mfh_harness::cli::run;
use mfh_harness::plan::plan;
use mfh_harness::scene::{Sampling, Scene};
use mfh_reference::{Masking, ModelSpec};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/scenes")
        .join(name)
}

fn load(name: &str) -> Scene {
    Scene::load(&example(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The check ids planned for one material.
fn checks_of(scene: &Scene, material: &str) -> BTreeSet<String> {
    let tag = format!("material `{material}` (");
    plan(scene, Profile::Quick)
        .iter()
        .filter(|p| p.why.contains(&tag))
        .map(|p| p.check.clone())
        .collect()
}

fn not_audited(scene: &Scene) -> Vec<String> {
    scene.not_audited.iter().map(|n| n.to_string()).collect()
}

const MASKING_CHECKS: &[&str] = &[
    "smith.g1_g2",
    "smith.identities",
    "smith.lambda_route",
    "smith.white_furnace",
];
const NORMAL_SAMPLING: &[&str] = &[
    "sampling.batch_agrees",
    "sampling.chi2",
    "sampling.ks_marginals",
    "sampling.lambda_monte_carlo",
    "sampling.pdf_consistency",
    "sampling.pdf_jacobian",
];
const VISIBLE_SAMPLING: &[&str] = &[
    "sampling.chi2_visible",
    "sampling.pdf_visible_normalization",
    "sampling.visible_jacobian",
];
const EVERY_MATERIAL: &[&str] = &[
    "normalization.projected_area",
    "stability.extremes",
    "stability.incidence",
];
/// The checks of a reference BSDF (roughconductor and roughdielectric name one).
const BSDF_CHECKS: &[&str] = &[
    "bsdf.albedo",
    "bsdf.chi2",
    "bsdf.energy",
    "bsdf.failure_rate",
    "bsdf.jacobian",
    "bsdf.ndf_consistency",
    "bsdf.reciprocity",
    "bsdf.sample_consistency",
    "bsdf.stability",
];
/// Certified double-double values of D and Λ: isotropic models only.
const ISOTROPIC: &[&str] = &["precise.closed_form"];

fn set(groups: &[&[&str]]) -> BTreeSet<String> {
    groups
        .iter()
        .flat_map(|g| g.iter().map(|s| s.to_string()))
        .collect()
}

#[test]
fn conductor_plans_ggx_with_separable_masking_and_visible_normals() {
    let s = load("conductor.xml");
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    assert_eq!(m.name, "gold");
    assert_eq!(
        m.model,
        Some(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
            alpha: Some(0.2),
            alpha_x: None,
            alpha_y: None
        }))
    );
    assert_eq!(m.masking, Some(Masking::Uncorrelated));
    assert_eq!(m.sampling, Some(Sampling::VisibleNormals));
    assert_eq!(
        checks_of(&s, "gold"),
        set(&[
            EVERY_MATERIAL,
            ISOTROPIC,
            MASKING_CHECKS,
            NORMAL_SAMPLING,
            VISIBLE_SAMPLING,
            BSDF_CHECKS
        ])
    );
    // Errata and claims are planned only where they concern a family or effect the scene
    // uses (errata::Scope): none of document 001's concern a GGX material alone.
    let planned = plan(&s, Profile::Quick);
    let others: BTreeSet<&str> = planned
        .iter()
        .filter(|p| !p.why.contains("material `gold`"))
        .map(|p| p.check.split('.').next().unwrap())
        .collect();
    assert_eq!(others, BTreeSet::new());
    assert!(planned
        .iter()
        .filter(|p| p.check.starts_with("errata."))
        .all(|p| p.why.contains("001")));
    assert_eq!(
        not_audited(&s),
        [
            "not audited: roughconductor material (gold) the named material `Au` is not read \
             (mfh has no table of Mitsuba's spectral indices): the BSDF is audited with n = 0.2, \
             k = 3",
            "not audited: shape sphere (ball) is not a BSDF",
            "not audited: emitter constant (sky) is not a BSDF",
        ]
    );
}

#[test]
fn mixed_scene_walks_wrappers_params_and_refs_and_lists_the_rest() {
    let s = load("mixed.xml");
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["steel", "floor/floor_coat", "leaf/leaf_glass"]);
    // $dist = ggx, α_u = 0.05, α_v = $floor_alpha = 0.3; referenced twice, planned once.
    assert_eq!(
        s.materials[0].model,
        Some(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
            alpha: None,
            alpha_x: Some(0.05),
            alpha_y: Some(0.3)
        }))
    );
    // roughplastic's default distribution is Beckmann.
    assert_eq!(
        s.materials[1].model,
        Some(ModelSpec::Beckmann(
            mfh_reference::ndf::beckmann::BeckmannSpec {
                alpha: Some(0.3),
                alpha_x: None,
                alpha_y: None
            }
        ))
    );
    assert_eq!(s.materials[2].sampling, Some(Sampling::Normals));
    assert!(s
        .materials
        .iter()
        .all(|m| m.masking == Some(Masking::Uncorrelated)));
    assert_eq!(
        checks_of(&s, "leaf/leaf_glass"),
        set(&[
            EVERY_MATERIAL,
            ISOTROPIC,
            MASKING_CHECKS,
            NORMAL_SAMPLING,
            BSDF_CHECKS
        ])
    );
    assert_eq!(
        checks_of(&s, "steel"),
        set(&[
            EVERY_MATERIAL,
            MASKING_CHECKS,
            NORMAL_SAMPLING,
            VISIBLE_SAMPLING,
            BSDF_CHECKS
        ])
    );
    let na = not_audited(&s);
    for expected in [
        "not audited: integrator path (path@9:5) is not a BSDF",
        "not audited: sensor perspective (camera) is not a BSDF",
        "not audited: sampler independent (independent@15:9) is not a BSDF",
        "not audited: film hdrfilm (hdrfilm@18:9) is not a BSDF",
        "not audited: diffuse (worn/dust) has no microfacet model",
        "not audited: dielectric (glass) has no microfacet model",
        "not audited: diffuse (wall) has no microfacet model",
        "not audited: shape obj (pot) is not a BSDF",
        "not audited: emitter area (area@72:9) is not a BSDF",
    ] {
        assert!(
            na.iter().any(|n| n == expected),
            "{expected} not in {na:#?}"
        );
    }
    let scratched = na.iter().find(|n| n.contains("(scratched)")).unwrap();
    assert!(
        scratched.contains("`alpha` is a texture (bitmap)"),
        "{scratched}"
    );
    assert_eq!(na.len(), 12, "{na:#?}");
}

#[test]
fn anisotropic_principled_plans_its_ggx_lobe_and_gtr1_clear_coat() {
    let s = load("principled.xml");
    let aspect = (1.0f64 - 0.9 * 0.75).sqrt();
    match &s.materials[0].model {
        Some(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
            alpha: None,
            alpha_x: Some(x),
            alpha_y: Some(y),
        })) => {
            assert!((x - 0.25 / aspect).abs() < 1e-15 && (y - 0.25 * aspect).abs() < 1e-15)
        }
        other => panic!("{other:?}"),
    }
    let cc = &s.materials[1];
    assert_eq!(cc.name, "car_paint/clearcoat");
    match cc.model {
        Some(ModelSpec::Gtr(mfh_reference::ndf::gtr::GtrSpec { gamma, alpha })) => {
            assert_eq!(gamma, 1.0);
            assert!((alpha - 0.0604).abs() < 1e-15, "{alpha}");
        }
        ref other => panic!("{other:?}"),
    }
    assert_eq!(
        checks_of(&s, "car_paint"),
        set(&[
            EVERY_MATERIAL,
            MASKING_CHECKS,
            NORMAL_SAMPLING,
            VISIBLE_SAMPLING
        ])
    );
    // principled is no reference BSDF: no BSDF checks.
    // The clear coat samples normals and its masking (a GGX G1 at α = 0.25) is not audited.
    assert_eq!(
        checks_of(&s, "car_paint/clearcoat"),
        set(&[EVERY_MATERIAL, NORMAL_SAMPLING])
    );
    let na = not_audited(&s);
    assert!(na[0].starts_with("not audited: principled clearcoat masking (car_paint/clearcoat)"));
    assert_eq!(na[1], "not audited: shape ply (body) is not a BSDF");
    // GTR1 comes from document 004: its errata and claims are planned too.
    assert!(plan(&s, Profile::Quick)
        .iter()
        .any(|p| p.check.starts_with("claims.gtr")));
}

#[test]
fn malformed_xml_names_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("mfh-mitsuba-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("broken.xml");
    std::fs::write(
        &path,
        "<scene version=\"3.0.0\">\n  <bsdf type=\"roughconductor\">\n    <float name=\"alpha\" value=\"0.1\">\n  </bsdf>\n</scene>\n",
    )
    .unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    // The closing </bsdf> at line 4, column 3 does not match the open <float>.
    let prefix = format!("{}:4:3:", path.display());
    assert!(e.starts_with(&prefix), "{e}");
    // The same through the CLI: exit 2, the position on standard error.
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run(
        ["mfh", "plan", "--scene", path.to_str().unwrap()],
        &mut std::io::empty(),
        &mut out,
        &mut err,
    );
    assert_eq!(code, 2);
    assert!(String::from_utf8(err).unwrap().contains(&prefix));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plan_lists_not_audited_plugins_as_json_lines_and_in_the_table() {
    let scene = example("conductor.xml");
    let scene = scene.to_str().unwrap();
    let mut out = Vec::new();
    let code = run(
        ["mfh", "plan", "--scene", scene],
        &mut std::io::empty(),
        &mut out,
        &mut Vec::new(),
    );
    assert_eq!(code, 0);
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let na: Vec<&serde_json::Value> = lines
        .iter()
        .filter(|l| l["not_audited"].is_object())
        .collect();
    assert_eq!(na.len(), 3);
    assert_eq!(na[1]["not_audited"]["id"], "ball");
    assert_eq!(
        na[1]["why"],
        "not audited: shape sphere (ball) is not a BSDF"
    );
    let mut out = Vec::new();
    let code = run(
        ["mfh", "plan", "--scene", scene, "--format", "table"],
        &mut std::io::empty(),
        &mut out,
        &mut Vec::new(),
    );
    assert_eq!(code, 0);
    let table = String::from_utf8(out).unwrap();
    assert!(
        table.contains("sampling.chi2_visible")
            && table.contains("bsdf.chi2")
            && table.contains("3 not audited:"),
        "{table}"
    );
    assert_eq!(
        table
            .lines()
            .filter(|l| l.contains("material `gold` ("))
            .count(),
        lines.len()
            - 3
            - plan(&load("conductor.xml"), Profile::Quick)
                .iter()
                .filter(|p| !p.why.contains("gold"))
                .count()
    );
}

/// A scene file of `text` in the temp folder, with extension `ext`.
fn temp_scene(name: &str, ext: &str, text: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!(
        "mfh-scene-bsdf-{name}-{}.{ext}",
        std::process::id()
    ));
    std::fs::write(&path, text).unwrap();
    path
}

/// `mfh plan --scene path`: exit status, stdout, stderr.
fn mfh_plan(path: &std::path::Path) -> (i32, String, String) {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run(
        ["mfh", "plan", "--scene", path.to_str().unwrap()],
        &mut std::io::empty(),
        &mut out,
        &mut err,
    );
    (
        code,
        String::from_utf8(out).unwrap(),
        String::from_utf8(err).unwrap(),
    )
}

/// A JSON material's `bsdf` and a Mitsuba roughdielectric plan the BSDF checks
/// (`bsdf.chi2` and the rest) through `mfh plan`; bad values exit 2 naming the field.
#[test]
fn json_and_mitsuba_bsdf_materials_plan_the_bsdf_checks() {
    let json = temp_scene(
        "glass",
        "json",
        r#"{"name": "glass", "materials": [{"name": "glass", "bsdf": {"type": "dielectric",
            "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}}]}"#,
    );
    let xml = temp_scene(
        "glass",
        "xml",
        r#"<scene version="3.0.0"><bsdf type="roughdielectric" id="glass">
           <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/>
           <float name="int_ior" value="1.5"/></bsdf></scene>"#,
    );
    for (path, ndf_checks) in [(&json, false), (&xml, true)] {
        let (code, out, err) = mfh_plan(path);
        assert_eq!(code, 0, "{path:?}: {err}");
        let ids: BTreeSet<String> = out
            .lines()
            .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
            .filter_map(|v| v["check"].as_str().map(str::to_string))
            .collect();
        for id in BSDF_CHECKS {
            assert!(ids.contains(*id), "{path:?}: {id} not planned: {ids:?}");
        }
        // The JSON material names only a BSDF; the Mitsuba one its NDF too.
        assert_eq!(ids.contains("smith.g1_g2"), ndf_checks, "{path:?}: {ids:?}");
    }
    let bad_json = temp_scene(
        "bad",
        "json",
        r#"{"name": "bad", "materials": [{"name": "glass", "bsdf": {"type": "dielectric",
            "eta": 0.01, "ndf": {"family": "ggx", "alpha": 0.3}}}]}"#,
    );
    let bad_xml = temp_scene(
        "bad",
        "xml",
        r#"<scene version="3.0.0"><bsdf type="roughdielectric" id="glass">
           <string name="int_ior" value="water"/></bsdf></scene>"#,
    );
    for (path, needles) in [
        (&bad_json, &["`glass`", "bsdf.eta", "[0.1, 10]"][..]),
        (&bad_xml, &["int_ior", "water", "<float>"]),
    ] {
        let (code, out, err) = mfh_plan(path);
        assert_eq!(code, 2, "{path:?}");
        assert!(out.is_empty(), "{out}");
        for n in needles {
            assert!(err.contains(n), "{path:?}: {err} lacks {n}");
        }
    }
    for p in [json, xml, bad_json, bad_xml] {
        let _ = std::fs::remove_file(p);
    }
}

/// A 1 MiB scene of tens of thousands of plugins is refused with one short line naming the
/// count and the limit, and a scene under the limit with nothing to audit names the first few
/// and how many there are. Naming each anonymous plugin (`shape@line:column`) used to scan the
/// text from its start: 61 000 shapes took 21 s to be refused with a 3 MB error. The times are
/// printed, not asserted (`--nocapture`).
#[test]
fn a_scene_of_many_plugins_is_refused_in_one_short_line() {
    let many = format!(
        "<scene version=\"3.0.0\">{}</scene>",
        "<shape/>".repeat(61_000)
    );
    assert!(many.len() < 1 << 20);
    let path = temp_scene("many", "xml", &many);
    let t = std::time::Instant::now();
    let (code, _, err) = mfh_plan(&path);
    eprintln!(
        "61 000 shapes: refused in {:.3} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.len() < 400, "{} bytes: {}", err.len(), &err[..400]);
    assert!(
        err.contains("61000 plugin elements") && err.contains("limit of 10000"),
        "{err}"
    );

    // Under the limit, on one line (each position counted from the previous one), and with
    // nothing to audit: the first ten not-audited plugins and the count.
    let under = format!(
        "<scene version=\"3.0.0\">{}</scene>",
        "<shape type=\"sphere\"/>".repeat(9_000)
    );
    let path = temp_scene("under", "xml", &under);
    let t = std::time::Instant::now();
    let (code, _, err) = mfh_plan(&path);
    eprintln!(
        "9 000 shapes: refused in {:.3} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.len() < 1000, "{} bytes: {}", err.len(), &err[..1000]);
    assert!(
        err.contains("shape sphere (sphere@1:24)") && err.contains("… and 8990 more, 9000 in all"),
        "{err}"
    );
    let _ = std::fs::remove_file(&path);
}
