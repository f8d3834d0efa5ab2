//! `mfh selftest`: audit every mutant of the catalog at a profile for several seeds and print
//! the kill matrix, or (`--calibrate N`) run the false-alarm calibration; write report.json
//! (a `selftest` section) and report.html into `--out`.

use super::{ProfileArg, EXIT_BAD_INPUT, EXIT_FAIL, EXIT_PASS};
use crate::selftest::{self, calibrate, SelftestOptions, Subset};
use clap::{Args, ValueEnum};
use std::io::Write;
use std::path::PathBuf;

/// The most seeds `--seeds` accepts (each is a full audit of every mutant).
pub const MAX_SEEDS: usize = 100;

/// The most runs `--calibrate` accepts per test.
pub const MAX_CALIBRATION_RUNS: usize = 100_000;

/// The options of `mfh selftest`.
#[derive(Debug, Args)]
pub struct SelftestArgs {
    /// The audit profile of every mutant (calibration: whose sample counts).
    #[arg(long, value_enum, default_value = "quick")]
    pub profile: ProfileArg,
    /// How many seeds each mutant is audited at (1 to 100).
    #[arg(long, default_value_t = 3)]
    pub seeds: usize,
    /// Which mutants: the CI subset or all.
    #[arg(long, value_enum, default_value = "all")]
    pub subset: SubsetArg,
    /// Only the mutants whose id contains this text (with --calibrate: the samplers whose
    /// spec contains it, e.g. `ggx`).
    #[arg(long)]
    pub only: Option<String>,
    /// Instead of the mutants, run N seeded chi-square and KS runs of the correct GGX and
    /// Beckmann (α = 0.3) samplers (1 to 100 000).
    #[arg(long, value_name = "N")]
    pub calibrate: Option<usize>,
    /// Instead of the mutants, measure the profile's detectable sampler distortion: the
    /// tan²θ exponent off by 0.25, 0.5, 1, 2 % for GGX, Beckmann, STD, Hyper-Cauchy and GTR,
    /// caught by the chi-square and KS checks at every seed.
    #[arg(long, conflicts_with = "calibrate")]
    pub power: bool,
    /// Where report.json and report.html go.
    #[arg(long, default_value = "reports/selftest")]
    pub out: PathBuf,
    /// No line per audit on standard error.
    #[arg(long)]
    pub quiet: bool,
}

/// `--subset` as the command line spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SubsetArg {
    /// The representative subset CI runs.
    Ci,
    /// Every mutant.
    All,
}

/// Runs `mfh selftest`; returns the exit status: 0 every mutant killed at every seed by an
/// expected check, every control passed and the calibration (if run) within its bounds; 1
/// otherwise; 2 on bad input.
pub fn run(args: SelftestArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    if !(1..=MAX_SEEDS).contains(&args.seeds) {
        let _ = writeln!(
            stderr,
            "mfh selftest: --seeds {} is outside [1, {MAX_SEEDS}]",
            args.seeds
        );
        return EXIT_BAD_INPUT;
    }
    if let Some(n) = args.calibrate {
        if !(1..=MAX_CALIBRATION_RUNS).contains(&n) {
            let _ = writeln!(
                stderr,
                "mfh selftest: --calibrate {n} is outside [1, {MAX_CALIBRATION_RUNS}]"
            );
            return EXIT_BAD_INPUT;
        }
    }
    let options = SelftestOptions {
        profile: args.profile.profile(),
        seeds: SelftestOptions::seeds(args.seeds),
        subset: match args.subset {
            SubsetArg::Ci => Subset::Ci,
            SubsetArg::All => Subset::All,
        },
        filter: args.only.clone(),
        on_check: super::trace::events(),
    };
    if args.calibrate.is_none()
        && !args.power
        && selftest::selected(&options).is_empty()
        && !selftest::bsdf::any_selected(&options)
    {
        let _ = writeln!(
            stderr,
            "mfh selftest: --only {:?} matches no mutant of the {:?} subset",
            args.only.as_deref().unwrap_or(""),
            options.subset
        );
        return EXIT_BAD_INPUT;
    }
    let quiet = args.quiet;
    let progress = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let report = match args.calibrate {
        Some(n) => {
            let t = std::time::Instant::now();
            let mut report = selftest::SelftestReport::empty(&options);
            // `--only` picks the calibrated samplers by a substring of their spec.
            let models: Vec<&str> = calibrate::DEFAULT_MODELS
                .iter()
                .copied()
                .filter(|m| args.only.as_ref().is_none_or(|o| m.contains(o.as_str())))
                .collect();
            let only = |m: &str| args.only.as_ref().is_none_or(|o| m.contains(o.as_str()));
            let bsdf = only(calibrate::BSDF_MODEL);
            if models.is_empty() && !bsdf {
                let _ = writeln!(
                    stderr,
                    "mfh selftest: --only {:?} matches none of the calibrated samplers {:?}",
                    args.only.as_deref().unwrap_or(""),
                    calibrate::DEFAULT_MODELS
                );
                return EXIT_BAD_INPUT;
            }
            let calibration = calibrate::calibrate(&models, n, options.profile, Some(&progress))
                .and_then(|mut c| {
                    if bsdf {
                        c.tests.extend(calibrate::calibrate_bsdf(
                            n,
                            options.profile,
                            Some(&progress),
                        )?);
                    }
                    Ok(c)
                });
            match calibration {
                Ok(c) => {
                    report.calibration = Some(c);
                    report.wall_seconds = t.elapsed().as_secs_f64();
                }
                Err(e) => {
                    let _ = writeln!(stderr, "mfh selftest: {e}");
                    return EXIT_BAD_INPUT;
                }
            }
            report
        }
        None if args.power => {
            let t = std::time::Instant::now();
            let mut report = selftest::SelftestReport::empty(&options);
            report.power = Some(selftest::power::measure(
                options.profile,
                &options.seeds,
                Some(&progress),
            ));
            report.wall_seconds = t.elapsed().as_secs_f64();
            report
        }
        None => selftest::run(&options, Some(&progress)),
    };
    // The summary is the output: if it cannot be written the run does not succeed (the files
    // below are still written, then exit 2).
    let printed = super::write_stdout("selftest", stdout, stderr, |stdout| {
        write!(stdout, "{}", summary(&report))
    });
    if let Err(e) = std::fs::create_dir_all(&args.out) {
        let _ = writeln!(
            stderr,
            "mfh selftest: cannot create {}: {e}",
            args.out.display()
        );
        return EXIT_BAD_INPUT;
    }
    let json = args.out.join("report.json");
    if let Err(e) = std::fs::write(
        &json,
        crate::report::json::selftest_to_string(&report) + "\n",
    ) {
        let _ = writeln!(stderr, "mfh selftest: cannot write {}: {e}", json.display());
        return EXIT_BAD_INPUT;
    }
    let html = args.out.join("report.html");
    match crate::report::selftest_html::render_selftest(&report) {
        Ok(text) => {
            if let Err(e) = std::fs::write(&html, text) {
                let _ = writeln!(stderr, "mfh selftest: cannot write {}: {e}", html.display());
                return EXIT_BAD_INPUT;
            }
        }
        Err(e) => {
            let _ = writeln!(
                stderr,
                "mfh selftest: cannot render {}: {e}",
                html.display()
            );
            return EXIT_BAD_INPUT;
        }
    }
    let wrote = super::write_stdout("selftest", stdout, stderr, |stdout| {
        writeln!(stdout, "wrote {} and {}", json.display(), html.display())
    });
    if let Err(code) = printed.and(wrote) {
        return code;
    }
    if report.passed() {
        EXIT_PASS
    } else {
        EXIT_FAIL
    }
}

/// The terminal summary: the kill matrix, survivors, failed controls, unexpected passes and
/// the calibration figures.
pub fn summary(report: &selftest::SelftestReport) -> String {
    let mut s = String::new();
    use std::fmt::Write as _;
    if !report.mutants.is_empty() {
        let caught = report.mutants.iter().filter(|m| m.caught()).count();
        let _ = writeln!(
            s,
            "mfh selftest: {caught}/{} mutants caught at every one of {} seeds (profile {}), \
             {} controls, {:.1} s",
            report.mutants.len(),
            report.seeds.len(),
            report.profile.name(),
            report.controls.len(),
            report.wall_seconds
        );
        for m in &report.mutants {
            let cells: Vec<String> = m
                .runs
                .iter()
                .map(|r| {
                    if !r.killed {
                        "SURVIVED".to_string()
                    } else if !r.expected_hit {
                        format!("MISSED-EXPECTED({})", r.killers.join(","))
                    } else {
                        r.killers.join(",")
                    }
                })
                .collect();
            let _ = writeln!(s, "  {:<42} {}", m.id, cells.join(" | "));
        }
        for c in report.controls.iter().filter(|c| !c.passed) {
            let _ = writeln!(
                s,
                "control FAILED: {} seed {:#x}: {}",
                c.base,
                c.seed,
                c.failures.join("; ")
            );
        }
        for m in &report.mutants {
            for r in &m.runs {
                for u in &r.unexpected_passes {
                    let _ = writeln!(
                        s,
                        "unexpected pass under {} (seed {:#x}): {u}",
                        m.id, r.seed
                    );
                }
            }
        }
    }
    if !report.bsdf_mutants.is_empty() {
        let caught = report.bsdf_mutants.iter().filter(|m| m.caught()).count();
        let _ = writeln!(
            s,
            "mfh selftest: {caught}/{} BSDF mutants caught at every one of {} seeds (profile {}), \
             {} BSDF controls",
            report.bsdf_mutants.len(),
            report.seeds.len(),
            report.profile.name(),
            report.bsdf_controls.len(),
        );
        for m in &report.bsdf_mutants {
            let cells: Vec<String> = m
                .runs
                .iter()
                .map(|r| {
                    if !r.killed {
                        "SURVIVED".to_string()
                    } else {
                        r.killers.join(",")
                    }
                })
                .collect();
            let _ = writeln!(s, "  {:<42} {}", m.id, cells.join(" | "));
        }
        for c in report
            .bsdf_controls
            .iter()
            .filter(|c| !c.failures.is_empty())
        {
            let _ = writeln!(
                s,
                "BSDF control FAILED: {} seed {:#x}: {}",
                c.base,
                c.seed,
                c.failures.join("; ")
            );
        }
    }
    for line in report.survivors() {
        let _ = writeln!(s, "not caught: {line}");
    }
    if let Some(c) = &report.calibration {
        for t in &c.tests {
            let levels: Vec<String> = t
                .levels
                .iter()
                .map(|l| {
                    format!(
                        "α={}: {} in [{}, {}]{}",
                        l.alpha,
                        l.rejections,
                        l.interval[0],
                        l.interval[1],
                        if l.within { "" } else { " OUTSIDE" }
                    )
                })
                .collect();
            let _ = writeln!(
                s,
                "calibration {} {}: {} runs × {} samples, {}; uniformity D = {:.4}, p = {:.3}{}; \
                 {} sanity failures; {:.1} s",
                t.model,
                t.test,
                t.runs,
                t.samples,
                levels.join(", "),
                t.uniformity_statistic,
                t.uniformity_p_value,
                if t.uniformity_p_value >= calibrate::UNIFORMITY_LEVEL {
                    ""
                } else {
                    " NOT UNIFORM"
                },
                t.sanity_failures,
                t.seconds
            );
        }
    }
    for d in report.power.iter().flatten() {
        let at: Vec<String> = selftest::power::DISTORTIONS
            .iter()
            .map(|&e| {
                let runs: Vec<_> = d.runs.iter().filter(|r| r.distortion == e).collect();
                let caught = runs.iter().filter(|r| !r.killers.is_empty()).count();
                format!("{}%: {caught}/{}", e * 100.0, runs.len())
            })
            .collect();
        let _ = writeln!(
            s,
            "power {}: caught at {}; detectable at every seed: {}",
            d.model,
            at.join(", "),
            d.smallest
                .map(|e| format!("{} %", e * 100.0))
                .unwrap_or_else(|| "none of the distortions tried".into())
        );
    }
    let _ = writeln!(s, "{}", if report.passed() { "PASS" } else { "FAIL" });
    s
}
