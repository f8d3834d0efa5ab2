//! `mfh plan --format table`: the plan for people — one row per planned check (number, id,
//! model, case, statistical or not, why), then the totals per check id and what the scene file
//! holds that is not audited. JSON lines ([`crate::plan::describe`]) stay the default.

use crate::check::Planned;
use crate::scene::NotAudited;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Cuts `text` to at most `width` characters (an ellipsis marks a cut).
fn fit(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        text.to_string()
    } else {
        let mut s: String = text.chars().take(width.saturating_sub(1)).collect();
        s.push('…');
        s
    }
}

/// Renders a plan as a text table.
pub fn plan_table(plan: &[Planned], not_audited: &[NotAudited]) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{:>4}  {:<34} {:<40} {:<28} {:<4} why",
        "#", "check", "model", "case", "stat"
    );
    for (i, p) in plan.iter().enumerate() {
        let model = if p.model.is_null() {
            "-".to_string()
        } else {
            p.model.to_string()
        };
        let _ = writeln!(
            o,
            "{:>4}  {:<34} {:<40} {:<28} {:<4} {}",
            i + 1,
            fit(&p.check, 34),
            fit(&model, 40),
            fit(&p.case.to_string(), 28),
            if p.statistical { "yes" } else { "" },
            p.why
        );
    }
    let mut by_check: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for p in plan {
        let e = by_check.entry(p.check.as_str()).or_default();
        e.0 += 1;
        e.1 += usize::from(p.statistical);
    }
    let statistical: usize = by_check.values().map(|v| v.1).sum();
    let _ = writeln!(
        o,
        "\n{} checks planned ({statistical} statistical), by check id:",
        plan.len()
    );
    for (id, (n, s)) in &by_check {
        let _ = writeln!(
            o,
            "  {id:<34} {n:>5}{}",
            if *s > 0 { "  statistical" } else { "" }
        );
    }
    if !not_audited.is_empty() {
        let _ = writeln!(o, "\n{} not audited:", not_audited.len());
        for n in not_audited {
            let _ = writeln!(o, "  {n}");
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Profile;
    use crate::scene::Scene;

    #[test]
    fn one_row_per_check_totals_and_not_audited() {
        let scene = Scene::parse(
            r#"{"name": "t", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3},
                "sampling": "normals"}]}"#,
            "t",
        )
        .unwrap();
        let plan = crate::plan::plan(&scene, Profile::Quick);
        let na = [NotAudited {
            plugin: "diffuse".into(),
            id: "wall".into(),
            reason: "has no microfacet model".into(),
        }];
        let t = plan_table(&plan, &na);
        let rows = t
            .lines()
            .filter(|l| l.contains("material `a` (ggx)"))
            .count();
        let own = plan
            .iter()
            .filter(|p| p.why.contains("material `a`"))
            .count();
        assert_eq!(rows, own, "{t}");
        assert!(t.contains(&format!("{} checks planned", plan.len())), "{t}");
        assert!(
            t.contains("sampling.chi2") && t.contains("statistical"),
            "{t}"
        );
        assert!(
            t.contains("not audited: diffuse (wall) has no microfacet model"),
            "{t}"
        );
    }
}
