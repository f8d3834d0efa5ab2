//! Test-only numerical integration (double-exponential quadrature from the `quadrature` crate,
//! made adaptive by bisection): the independent oracle the closed-form unit tests use.

/// The most pieces one `integrate` call splits its interval into: the error target of a
/// piece near round-off is sometimes unreachable, and the test must then finish (with the
/// error estimate saying so) rather than bisect for ever.
const MAX_PIECES: usize = 400;

/// ∫_a^b f with relative accuracy `rel` (absolute floor `abs`): globally adaptive bisection
/// of the piece with the largest double-exponential error estimate, until the summed estimate
/// meets the target or `MAX_PIECES` pieces. Returns (value, estimate of the error).
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, rel: f64, abs: f64) -> (f64, f64) {
    let estimate = |lo: f64, hi: f64, tol: f64| {
        let o = quadrature::double_exponential::integrate(f, lo, hi, tol);
        (lo, hi, o.integral, o.error_estimate)
    };
    let whole = estimate(a, b, abs.max(1e-300));
    let mut pieces = vec![whole];
    loop {
        let value: f64 = pieces.iter().map(|p| p.2).sum();
        let error: f64 = pieces.iter().map(|p| p.3).sum();
        let target = (rel * value.abs()).max(abs);
        if error <= target || pieces.len() >= MAX_PIECES {
            return (value, error);
        }
        let (worst, _) = pieces
            .iter()
            .enumerate()
            .max_by(|x, y| x.1 .3.total_cmp(&y.1 .3))
            .expect("at least one piece");
        let (lo, hi, _, _) = pieces.swap_remove(worst);
        let mid = 0.5 * (lo + hi);
        let tol = 0.1 * target * (hi - lo) / (b - a).abs().max(f64::MIN_POSITIVE);
        pieces.push(estimate(lo, mid, tol));
        pieces.push(estimate(mid, hi, tol));
    }
}

/// ∫_a^∞ f by the substitution t = a + scale · ((1 − u)^{−4} − 1), u ∈ [0, 1): algebraic
/// tails down to t^{−1.25} become bounded integrands (heavy-tailed Student members), and cuts
/// at t − a = scale · {10⁻⁴ … 10⁸} resolve both narrow peaks and wide tails. `scale` should
/// be the width over which f decays.
pub fn integrate_tail(f: &dyn Fn(f64) -> f64, a: f64, scale: f64, rel: f64) -> f64 {
    const M: f64 = 4.0;
    let g = |u: f64| {
        let one_minus = 1.0 - u;
        let stretch = one_minus.powf(-M);
        let t = a + scale * (stretch - 1.0);
        let v = f(t) * scale * M * stretch / one_minus;
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    let mut cuts = vec![0.0];
    for v in [1e-4f64, 1e-2, 0.25, 1.0, 4.0, 16.0, 64.0, 1e3, 1e5, 1e8] {
        cuts.push(1.0 - (1.0 + v).powf(-1.0 / M));
    }
    cuts.push(1.0);
    // A rough pass fixes the magnitude, so that pieces where f is negligible stop at once
    // (an absolute floor) instead of chasing a relative target on a value of 0.
    let rough: f64 = cuts
        .windows(2)
        .map(|w| {
            quadrature::double_exponential::integrate(g, w[0], w[1], 1e-8)
                .integral
                .abs()
        })
        .sum();
    let floor = 0.05 * rel * rough;
    cuts.windows(2)
        .map(|w| integrate(&g, w[0], w[1], rel, floor).0)
        .sum()
}

/// ∫_{−∞}^{∞} f for an f centred at 0 with width `scale`.
pub fn integrate_line(f: &dyn Fn(f64) -> f64, scale: f64, rel: f64) -> f64 {
    integrate_tail(f, 0.0, scale, rel) + integrate_tail(&|t| f(-t), 0.0, scale, rel)
}

/// The relative difference |a − b| / |b| (absolute where b = 0).
pub fn rel_err(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}

/// The rows of one table of `reference/golden/student.json` (mpmath, 60 digits; see its
/// provenance block).
pub fn golden(table: &str) -> Vec<serde_json::Value> {
    let all: serde_json::Value =
        serde_json::from_str(include_str!("../golden/student.json")).expect("golden JSON");
    all[table].as_array().expect("golden table").clone()
}

/// The rows of `reference/golden/beckmann.json` (Beckmann Λ(a), mpmath, 60 digits; see its
/// provenance block).
pub fn golden_beckmann() -> Vec<serde_json::Value> {
    let all: serde_json::Value =
        serde_json::from_str(include_str!("../golden/beckmann.json")).expect("golden JSON");
    all["lambda"].as_array().expect("golden table").clone()
}

/// A table of `reports/accuracy-other-documents.md` built by an accuracy test: printed as it is
/// built, then compared with the file's section between `<!-- generated: NAME -->` and
/// `<!-- end: NAME -->` — or, with `MFH_WRITE_REPORTS=1`, written into it. So the tracked
/// tables are this test's output, and the test fails when they are stale.
pub struct ReportTable {
    name: &'static str,
    text: String,
}

impl ReportTable {
    /// An empty table for the section `name`.
    pub fn new(name: &'static str) -> Self {
        Self {
            name,
            text: String::new(),
        }
    }

    /// Prints a line and appends it to the table.
    pub fn line(&mut self, line: String) {
        println!("{line}");
        self.text.push_str(&line);
        self.text.push('\n');
    }

    /// Compares the table with its section of the report (or writes it there).
    ///
    /// # Panics
    /// If the report or its markers are missing, or the section differs from the table.
    pub fn check_report(&self) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../reports/accuracy-other-documents.md");
        let report = std::fs::read_to_string(&path).expect("reports/accuracy-other-documents.md");
        let begin = format!("<!-- generated: {} -->\n", self.name);
        let end = format!("<!-- end: {} -->", self.name);
        let start = report.find(&begin).expect("the section's begin marker") + begin.len();
        let stop = start
            + report[start..]
                .find(&end)
                .expect("the section's end marker");
        if std::env::var_os("MFH_WRITE_REPORTS").is_some() {
            let updated = format!("{}{}{}", &report[..start], self.text, &report[stop..]);
            std::fs::write(&path, updated).expect("write reports/accuracy-other-documents.md");
            return;
        }
        assert!(
            report[start..stop] == self.text,
            "reports/accuracy-other-documents.md, section {}, is stale: regenerate it with \
             `MFH_EXTENSIVE=1 MFH_WRITE_REPORTS=1 cargo test -p mfh-reference --release \
             accuracy_table_`\n--- now ---\n{}--- in the file ---\n{}",
            self.name,
            self.text,
            &report[start..stop]
        );
    }
}

/// `tline!(table, "…", args)`: a formatted line of a [`ReportTable`].
macro_rules! tline {
    ($table:expr, $($arg:tt)*) => {
        $table.line(format!($($arg)*))
    };
}
pub(crate) use tline;
