//! The renderer's CI gate: its own GGX and Beckmann pass mfh's audit, and each deliberately
//! wrong variant fails on the check that sees its defect.

use mfh_harness::model::{Ndf, NormalSampler, Smith, Vec3};
use mfh_harness::{Audit, Profile};
use mfh_outside_user::{Defect, Family, Microfacet};
use mfh_reference::Masking;

/// The thin wrapper a renderer writes: its own type behind mfh's capability traits.
struct Gated(Microfacet);

impl Ndf for Gated {
    fn d(&self, m: Vec3) -> f64 {
        self.0.d(m)
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }
}

impl Smith for Gated {
    fn lambda(&self, w: Vec3) -> f64 {
        self.0.lambda(w)
    }
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
        let facing = |w: Vec3| w[2] > 0.0 && w[0] * m[0] + w[1] * m[1] + w[2] * m[2] > 0.0;
        if !(facing(wo) && facing(wi)) {
            return 0.0;
        }
        match masking {
            Masking::Uncorrelated => self.g1(wo, m) * self.g1(wi, m),
            Masking::HeightCorrelated => self.0.g2_height_correlated(wo, wi),
        }
    }
}

impl NormalSampler for Gated {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        self.0.sample_wm(u)
    }
    fn pdf_wm(&self, m: Vec3) -> f64 {
        self.0.pdf_wm(m)
    }
}

fn spec(m: &Microfacet) -> String {
    let family = match m.family {
        Family::Ggx => "ggx",
        Family::Beckmann => "beckmann",
    };
    format!(
        r#"{{"family":"{family}","alpha_x":{},"alpha_y":{}}}"#,
        m.alpha_x, m.alpha_y
    )
}

fn audit(m: Microfacet) -> mfh_harness::run::AuditReport {
    gate(&Gated(m))
}

fn gate(g: &Gated) -> mfh_harness::run::AuditReport {
    let m = g.0;
    Audit::of(g)
        .name(&format!(
            "{:?} α = ({}, {}), defect {:?}",
            m.family, m.alpha_x, m.alpha_y, m.defect
        ))
        .profile(Profile::Ci)
        .against(&spec(&m))
        .run()
}

/// The natural form on edition 2021 (this crate's): the gate as the tail expression of a
/// function that owns its model. With a borrowing `run` the builder was a temporary that
/// outlived the model (E0597); this test compiling is half the proof, passing the other half.
fn gate_owned(m: Microfacet) -> bool {
    let g = Gated(m);
    Audit::of(&g).profile(Profile::Ci).run().passed()
}

#[test]
fn the_gate_is_a_tail_expression_over_an_owned_model() {
    assert!(gate_owned(Microfacet::new(Family::Ggx, 0.3)));
}

#[test]
fn the_renderers_correct_models_pass() {
    for m in [
        Microfacet::new(Family::Ggx, 0.3),
        Microfacet::anisotropic(Family::Ggx, 0.1, 0.4),
        Microfacet::new(Family::Beckmann, 0.3),
        Microfacet::anisotropic(Family::Beckmann, 0.3, 0.15),
    ] {
        let report = audit(m);
        assert!(report.records.len() > 20, "{}", report.records.len());
        report.assert_pass();
    }
}

/// Audits the variant of `base` with `defect` and asserts that `check` is among the checks
/// that failed (other checks may see the defect too).
fn fails_on(base: Microfacet, defect: Defect, check: &str) {
    let report = audit(base.with(defect));
    let failed = report.failed_checks();
    assert!(
        failed.contains(&check),
        "{defect:?} did not fail {check} (failed: {failed:?})"
    );
}

/// One test per wrong model, each named for its defect.
macro_rules! wrong_model {
    ($($name:ident: $defect:ident => $check:literal,)*) => {$(
        #[test]
        fn $name() {
            let base = if Defect::$defect == Defect::AxesSwappedInD {
                Microfacet::anisotropic(Family::Ggx, 0.1, 0.4)
            } else {
                Microfacet::new(Family::Ggx, 0.3)
            };
            fails_on(base, Defect::$defect, $check);
        }
    )*};
}

wrong_model! {
    normalization_off_by_one_percent: NormalizationOnePercent => "normalization.projected_area",
    lambda_wrong_above_1_3_only: LambdaWrongAboveOnePointThree => "smith.lambda_route",
    sampler_exponent_off: SamplerExponent => "sampling.chi2",
    phi_over_half_the_circle: HalfCirclePhi => "sampling.chi2",
    pdf_off_its_sampler_by_half_a_percent: PdfMismatch => "sampling.pdf_jacobian",
    normal_below_the_horizon_at_u_zero: BelowHorizonAtUZero => "stability.incidence",
    nan_at_exactly_normal_incidence: NanAtNormalIncidence => "stability.incidence",
    height_correlated_g2_replaced_by_uncorrelated: G2Uncorrelated => "smith.g1_g2",
    axes_swapped_in_d_only: AxesSwappedInD => "smith.lambda_route",
}

/// A model that panics or answers NaN inside its methods gives failing records; the audit
/// itself neither panics nor stops the other checks.
#[test]
fn a_misbehaving_model_gives_failing_records_not_a_panic() {
    struct Panics;
    impl Ndf for Panics {
        fn d(&self, m: Vec3) -> f64 {
            if m[2] < 0.5 {
                panic!("renderer bug: D called at m_z = {}", m[2]);
            }
            1.0 / std::f64::consts::PI
        }
    }
    let report = Audit::of(&Panics).profile(Profile::Ci).run();
    assert!(!report.passed());
    let messages: Vec<String> = report
        .records
        .iter()
        .filter_map(|r| match &r.verdict {
            mfh_harness::record::Verdict::Error { message } => Some(message.clone()),
            _ => None,
        })
        .collect();
    assert!(
        messages.iter().any(|m| m.contains("renderer bug")),
        "{messages:?}"
    );
}
