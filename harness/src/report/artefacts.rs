//! Artefact files of records that carry data ([`RecordData`]): the chi-square count tables
//! (`chi2_observed.json`, `chi2_expected.json`) and heat maps (`chi2_observed.svg`,
//! `chi2_expected.svg`, `chi2_difference.svg`) in `out/chi2/<model and case>/`, the KS
//! marginal curves in `out/ks/<model and case>/ks_marginal.json`. The same functions serve
//! `mfh audit` and `mfh chi2 --out`.

#[cfg(feature = "html")]
use super::heat_map::{heat_map_svg, HeatMap};
#[cfg(feature = "html")]
use super::plot::{ColourScale, PlotError};
use crate::record::{CheckRecord, RecordData};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A file-name-safe folder name for a model and case: their compact JSON with every run of
/// characters outside `[A-Za-z0-9.-]` turned into one `_`; past 120 characters, the first 111
/// and 8 hex digits of a hash (FNV-1a) of the whole, so that long names stay distinct.
pub fn folder_name(model: &Value, case: &Value) -> String {
    let text = format!("{model}_{case}");
    let mut out = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    let mut out = out.trim_matches('_').to_string();
    if out.len() > 120 {
        let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        out = format!("{}_{:08x}", &out[..111], hash >> 32);
    }
    if out.is_empty() {
        "case".to_string()
    } else {
        out
    }
}

pub use super::text::{case_name, model_name};

/// The folder (relative to the output folder) a record's artefacts go to, if it has data.
pub fn relative_folder(record: &CheckRecord) -> Option<PathBuf> {
    let kind = match record.data.as_ref()? {
        RecordData::Chi2Table { .. } | RecordData::SphereChi2Table { .. } => "chi2",
        RecordData::KsMarginal { .. } => "ks",
        RecordData::Curve { .. } => "curves",
    };
    Some(Path::new(kind).join(folder_name(&record.model, &record.case)))
}

/// The file names a record's data is written to (in [`relative_folder`]); the heat maps
/// only with the `html` feature (they are drawn with plotters).
pub fn file_names(data: &RecordData) -> &'static [&'static str] {
    match data {
        RecordData::Chi2Table { .. } => &[
            "chi2_observed.json",
            "chi2_expected.json",
            #[cfg(feature = "html")]
            "chi2_observed.svg",
            #[cfg(feature = "html")]
            "chi2_expected.svg",
            #[cfg(feature = "html")]
            "chi2_difference.svg",
        ],
        RecordData::SphereChi2Table { .. } => &[
            "upper_chi2_observed.json",
            "upper_chi2_expected.json",
            "lower_chi2_observed.json",
            "lower_chi2_expected.json",
            #[cfg(feature = "html")]
            "upper_chi2_observed.svg",
            #[cfg(feature = "html")]
            "upper_chi2_expected.svg",
            #[cfg(feature = "html")]
            "upper_chi2_difference.svg",
            #[cfg(feature = "html")]
            "lower_chi2_observed.svg",
            #[cfg(feature = "html")]
            "lower_chi2_expected.svg",
            #[cfg(feature = "html")]
            "lower_chi2_difference.svg",
        ],
        RecordData::KsMarginal { .. } => &["ks_marginal.json"],
        RecordData::Curve { .. } => &["curve.json"],
    }
}

/// One hemisphere of a sphere table.
pub struct Hemisphere<'a> {
    /// The artefacts' file prefix (`upper`, `lower`).
    pub prefix: &'static str,
    /// The title suffix.
    pub side: &'static str,
    /// Observed counts per cell.
    pub observed: &'a [u64],
    /// Expected counts per cell.
    pub expected: &'a [f64],
    /// Its cells' cos θ edges (empty: equal).
    pub z_edges: &'a [f64],
    /// Its cells' φ edges (empty: equal).
    pub phi_edges: &'a [f64],
}

/// The hemispheres of a sphere table, upper then lower (none for another kind of data).
pub fn hemispheres(data: &RecordData) -> Vec<Hemisphere<'_>> {
    match data {
        RecordData::SphereChi2Table {
            upper_observed,
            upper_expected,
            lower_observed,
            lower_expected,
            upper_z_edges,
            upper_phi_edges,
            lower_z_edges,
            lower_phi_edges,
            ..
        } => vec![
            Hemisphere {
                prefix: "upper",
                side: "above the surface",
                observed: upper_observed,
                expected: upper_expected,
                z_edges: upper_z_edges,
                phi_edges: upper_phi_edges,
            },
            Hemisphere {
                prefix: "lower",
                side: "below the surface (mirrored)",
                observed: lower_observed,
                expected: lower_expected,
                z_edges: lower_z_edges,
                phi_edges: lower_phi_edges,
            },
        ],
        _ => Vec::new(),
    }
}

/// What the chi-square heat maps show, for the page that shows them: densities, because the
/// cells are unequal.
pub const CHI2_MAPS_NOTE: &str = "The observed and expected maps show densities, counts / (N · \
     cell solid angle) per steradian (N the samples drawn), not counts: the chi-square cells \
     follow the lobe's quantiles (or equal areas) and are unequal in solid angle, so counts \
     would make the lobe's small cells look dark. The residual map is per cell, (O − E)/√E. \
     Axes in radians: φ across, θ down.";

/// The solid angle of each cell of a (cos θ, φ) grid, row-major: (z_{i+1} − z_i)(φ_{j+1} −
/// φ_j), the edges i/R and 2πj/C where none are given.
pub fn cell_solid_angles(
    (rows, columns): (usize, usize),
    (z_edges, phi_edges): (&[f64], &[f64]),
) -> Vec<f64> {
    let z = |i: usize| {
        if z_edges.len() == rows + 1 {
            z_edges[i]
        } else {
            i as f64 / rows as f64
        }
    };
    let phi = |j: usize| {
        if phi_edges.len() == columns + 1 {
            phi_edges[j]
        } else {
            std::f64::consts::TAU * j as f64 / columns as f64
        }
    };
    (0..rows)
        .flat_map(|i| (0..columns).map(move |j| (z(i + 1) - z(i)) * (phi(j + 1) - phi(j))))
        .collect()
}

/// The three chi-square heat maps (observed, expected, (O − E)/√E) as (file name, SVG), titled
/// `title` plus what each shows. Observed and expected are densities, count / (`samples` ·
/// cell solid angle) per steradian ([`CHI2_MAPS_NOTE`]), on one linear scale (0 to the
/// largest of either); the difference is per cell and diverging, ±max(4, largest |residual|),
/// grey where E = O = 0, magenta where samples fell in a cell of zero expected count.
#[cfg(feature = "html")]
pub fn chi2_heat_maps(
    title: &str,
    (rows, columns): (usize, usize),
    (z_edges, phi_edges): (&[f64], &[f64]),
    samples: u64,
    observed: &[u64],
    expected: &[f64],
) -> Result<Vec<(&'static str, String)>, PlotError> {
    let solid_angles = cell_solid_angles((rows, columns), (z_edges, phi_edges));
    let n = samples.max(1) as f64;
    let density = |count: f64, omega: f64| {
        if omega > 0.0 {
            count / (n * omega)
        } else {
            f64::NAN
        }
    };
    let observed_density: Vec<f64> = observed
        .iter()
        .zip(&solid_angles)
        .map(|(&o, &w)| density(o as f64, w))
        .collect();
    let expected_density: Vec<f64> = expected
        .iter()
        .zip(&solid_angles)
        .map(|(&e, &w)| density(e, w))
        .collect();
    let max = observed_density
        .iter()
        .chain(&expected_density)
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let difference: Vec<f64> = observed
        .iter()
        .zip(expected)
        .map(|(&o, &e)| match (o as f64, e) {
            (o, e) if e > 0.0 => (o - e) / e.sqrt(),
            (o, _) if o > 0.0 => f64::INFINITY,
            _ => f64::NAN,
        })
        .collect();
    let limit = difference
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(4.0f64, |a, v| a.max(v.abs()));
    let densities = ColourScale::Sequential { min: 0.0, max };
    let density_unit = "density (sr⁻¹)";
    let maps = [
        (
            "chi2_observed.svg",
            "observed density, counts / (N · cell solid angle)",
            density_unit,
            &observed_density,
            densities,
        ),
        (
            "chi2_expected.svg",
            "expected density, counts / (N · cell solid angle)",
            density_unit,
            &expected_density,
            densities,
        ),
        (
            "chi2_difference.svg",
            "residual per cell, (O − E)/√E",
            "(O − E)/√E",
            &difference,
            ColourScale::Diverging { limit },
        ),
    ];
    maps.into_iter()
        .map(|(name, what, quantity, values, scale)| {
            let svg = heat_map_svg(&HeatMap {
                title,
                subtitle: what,
                quantity,
                rows,
                columns,
                values,
                scale,
                z_edges,
                phi_edges,
            })?;
            Ok((name, svg))
        })
        .collect()
}

/// The count tables as JSON text: (`chi2_observed.json`, `chi2_expected.json`), rows of cos θ
/// (row 0 at the horizon), columns of φ from 0.
pub fn chi2_tables(
    generated_by: &str,
    (rows, columns): (usize, usize),
    (z_edges, phi_edges): (&[f64], &[f64]),
    samples: u64,
    seed: u64,
    observed: &[u64],
    expected: &[f64],
) -> [(&'static str, String); 2] {
    let layout = match (z_edges.is_empty(), phi_edges.is_empty()) {
        (true, true) => format!(
            "rows: cos θ in [i/R, (i+1)/R), row 0 at the horizon; columns: φ in \
             [2πj/{columns}, 2π(j+1)/{columns}); R = {rows}"
        ),
        _ => format!(
            "rows: cos θ in [z_edges[i], z_edges[i+1]), row 0 at the horizon; columns: φ in \
             [phi_edges[j], phi_edges[j+1]) (empty edges: i/R and 2πj/{columns}); R = {rows}"
        ),
    };
    let table = |counts: Value| {
        let value = json!({
            "generated_by": generated_by,
            "layout": layout,
            "samples": samples,
            "seed": seed,
            "rows": rows,
            "columns": columns,
            "z_edges": z_edges,
            "phi_edges": phi_edges,
            "counts": counts,
        });
        format!("{value:#}\n")
    };
    let o: Vec<&[u64]> = observed.chunks(columns.max(1)).collect();
    let e: Vec<&[f64]> = expected.chunks(columns.max(1)).collect();
    [
        ("chi2_observed.json", table(json!(o))),
        ("chi2_expected.json", table(json!(e))),
    ]
}

/// Why an artefact could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ArtefactError {
    /// A plot could not be drawn.
    #[cfg(feature = "html")]
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A file or folder could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

fn write_file(path: PathBuf, contents: &str) -> Result<PathBuf, ArtefactError> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| ArtefactError::Io {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    std::fs::write(&path, contents).map_err(|source| ArtefactError::Io {
        path: path.clone(),
        source,
    })?;
    Ok(path)
}

/// Writes the files of one record's data into `folder`; returns the paths written (in
/// [`file_names`] order).
pub fn write_record_data(
    folder: &Path,
    title: &str,
    generated_by: &str,
    data: &RecordData,
) -> Result<Vec<PathBuf>, ArtefactError> {
    let mut files: Vec<(&str, String)> = Vec::new();
    match data {
        RecordData::Chi2Table {
            rows,
            columns,
            samples,
            seed,
            observed,
            expected,
            z_edges,
            phi_edges,
        } => {
            files.extend(chi2_tables(
                generated_by,
                (*rows, *columns),
                (z_edges, phi_edges),
                *samples,
                *seed,
                observed,
                expected,
            ));
            #[cfg(feature = "html")]
            files.extend(chi2_heat_maps(
                title,
                (*rows, *columns),
                (z_edges, phi_edges),
                *samples,
                observed,
                expected,
            )?);
            #[cfg(not(feature = "html"))]
            let _ = title;
        }
        RecordData::SphereChi2Table {
            rows,
            columns,
            samples,
            seed,
            ..
        } => {
            // The names are the `file_names` entries, which must be 'static: the prefixed
            // names are matched back from that list.
            let names = file_names(data);
            let named = |n: String| -> &'static str {
                names
                    .iter()
                    .copied()
                    .find(|x| *x == n)
                    .unwrap_or("chi2.json")
            };
            for h in hemispheres(data) {
                let edges = (h.z_edges, h.phi_edges);
                for (name, text) in chi2_tables(
                    generated_by,
                    (*rows, *columns),
                    edges,
                    *samples,
                    *seed,
                    h.observed,
                    h.expected,
                ) {
                    files.push((named(format!("{}_{name}", h.prefix)), text));
                }
                #[cfg(feature = "html")]
                for (name, svg) in chi2_heat_maps(
                    &format!("{title} · {}", h.side),
                    (*rows, *columns),
                    edges,
                    *samples,
                    h.observed,
                    h.expected,
                )? {
                    files.push((named(format!("{}_{name}", h.prefix)), svg));
                }
                #[cfg(not(feature = "html"))]
                let _ = title;
            }
        }
        RecordData::KsMarginal { .. } => {
            files.push(("ks_marginal.json", format!("{:#}\n", json!(data))));
        }
        RecordData::Curve { .. } => files.push(("curve.json", format!("{:#}\n", json!(data)))),
    }
    files
        .into_iter()
        .map(|(name, text)| write_file(folder.join(name), &text))
        .collect()
}

pub use super::text::record_title;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folder_names_are_safe_and_distinct() {
        let name = folder_name(
            &json!({"family": "ggx", "alpha": 0.3}),
            &json!({"samples": 10}),
        );
        assert_eq!(name, "alpha_0.3_family_ggx_samples_10");
        let long = |v: f64| {
            folder_name(
                &json!({"family": "piecewise_linear", "x": {"theta": [0.0, 0.5, 1.0, 1.5],
                        "value": [1.0, 0.6, 0.1, 0.0]}, "y": {"theta": [0.0, 0.3, 0.9, 1.5],
                        "value": [2.0, 0.8, 0.05, v]}}),
                &json!({"samples": 200000, "resolution": 16}),
            )
        };
        let (a, b) = (long(0.0), long(1e-3));
        assert!(a.len() == 120 && b.len() == 120 && a != b, "{a} {b}");
        assert!(a
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c)));
    }

    #[test]
    fn a_chi2_table_is_written_as_tables_and_three_heat_maps() {
        let dir = std::env::temp_dir().join(format!("mfh-artefacts-{}", std::process::id()));
        let data = RecordData::Chi2Table {
            rows: 2,
            columns: 4,
            samples: 12,
            seed: 5,
            observed: vec![0, 1, 2, 3, 0, 1, 2, 3],
            expected: vec![0.0, 1.5, 1.5, 3.0, 0.5, 1.0, 2.0, 2.5],
            z_edges: vec![0.0, 0.9, 1.0],
            phi_edges: vec![0.0, 1.0, 3.0, 4.0, std::f64::consts::TAU],
        };
        let paths = write_record_data(&dir, "ggx alpha=0.3", "test", &data).unwrap();
        assert_eq!(paths.len(), 5);
        for (p, name) in paths.iter().zip(file_names(&data)) {
            assert!(p.ends_with(name), "{p:?}");
            let text = std::fs::read_to_string(p).unwrap();
            if name.ends_with(".svg") {
                assert!(text.starts_with("<svg") && text.contains("ggx alpha=0.3"));
            } else {
                let v: Value = serde_json::from_str(&text).unwrap();
                assert_eq!(v["counts"].as_array().unwrap().len(), 2);
                assert_eq!(v["counts"][0].as_array().unwrap().len(), 4);
            }
        }
        // A folder under a regular file cannot be created: a typed error naming the path.
        let blocked = dir.join("chi2_observed.json").join("x");
        let e = write_record_data(&blocked, "t", "test", &data).unwrap_err();
        assert!(e.to_string().contains("chi2_observed.json"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
