//! Mitsuba 3 XML scenes → an mfh [`Scene`]: the microfacet BSDFs a Mitsuba scene already uses
//! become materials with their NDF, masking and sampling; every other plugin is listed as not
//! audited, with the reason ("Scenes a renderer already has").
//!
//! What is read, and from where in Mitsuba 3 (src/bsdfs/*.cpp, include/mitsuba/render/
//! microfacet.h, as documented in each plugin's parameter table):
//!
//! | plugin | NDF | roughness (default) | sampling |
//! |---|---|---|---|
//! | `roughconductor`, `roughdielectric` | `distribution` beckmann (default) / ggx | `alpha` (0.1), or `alpha_u` + `alpha_v` | `sample_visible` (true) |
//! | `roughplastic` | `distribution` beckmann (default) / ggx | `alpha` (0.1), isotropic | `sample_visible` (true) |
//! | `principled`, `principledthin` | GGX | `roughness` (0.5), `anisotropic` (0): α = max(10⁻³, r²/a), max(10⁻³, r²·a), a = √(1 − 0.9·anisotropic) (principledhelpers.h `calc_dist_params`) | visible normals (the `MicrofacetDistribution` default) |
//! | `principled` clearcoat (when `clearcoat` ≠ 0) | GTR1 = GTR γ = 1 | α = lerp(0.1, 0.001, `clearcoat_gloss` (0)) | normals (`GTR1Isotropic::sample`) |
//!
//! `roughconductor` and `roughdielectric` also name a reference BSDF, whose BSDF
//! checks are planned besides the NDF's: a roughdielectric's η = `int_ior`/`ext_ior` (floats;
//! absent: bk7 1.5046 / air 1.000277; named IORs are refused, mfh has no table), a
//! roughconductor's n + ik = `eta` + i`k` (floats; absent or spectral: 0.2 + 3i, and a spectral
//! index is listed as not audited); masking uncorrelated, exact Fresnel, radiance transport.
//!
//! Masking: Mitsuba 3's `MicrofacetDistribution::G` is "Smith's separable shadowing-masking
//! approximation", G1(wi, m)·G1(wo, m) — the uncorrelated G2 (document 001 eq 22), not the
//! height-correlated form. Mitsuba clamps α ≥ 10⁻⁴ (`MicrofacetDistribution::configure`); so
//! does this reader. The clearcoat lobe masks with a GGX G1 at α = 0.25 (`clearcoat_G`), which
//! is not the Smith G of its own NDF: that masking is listed as not audited.
//!
//! Wrappers `twosided`, `blendbsdf`, `mask`, `bumpmap` and `normalmap` are walked into (their
//! nested BSDFs are materials named `outer/inner`); `<ref id>` to a named BSDF audits it once,
//! under its own id. `<default name value>` and `$name` substitution in attribute values work
//! as in Mitsuba; `<include>` is refused (mfh reads one self-contained file). Every error names
//! the file, line and column.

mod bsdf;
mod position;

use crate::scene::{Material, NotAudited, Sampling, Scene, SceneError};
use mfh_reference::{Masking, ModelSpec};
use roxmltree::{Document, Node};
use std::collections::{BTreeMap, BTreeSet};

/// Mitsuba's smallest roughness (`MicrofacetDistribution::configure`: α = max(α, 10⁻⁴)).
pub const MITSUBA_ALPHA_MIN: f64 = 1e-4;

/// Mitsuba's default `int_ior` of a roughdielectric, its named IOR `bk7` (ior.h).
pub const MITSUBA_BK7_IOR: f64 = 1.5046;

/// Mitsuba's default `ext_ior` of a roughdielectric, its named IOR `air` (ior.h).
pub const MITSUBA_AIR_IOR: f64 = 1.000277;

/// The complex index (n, k) a roughconductor is audited with when its `eta`/`k` are not given
/// as floats (Mitsuba's default is the ideal mirror `material="none"`, which has no finite
/// index): a bright metal, roughly silver at 550 nm.
pub const DEFAULT_CONDUCTOR_NK: (f64, f64) = (0.2, 3.0);

/// Plugin element names of Mitsuba 3 (everything else with a `name` is a property).
const PLUGIN_TAGS: &[&str] = &[
    "bsdf",
    "shape",
    "emitter",
    "sensor",
    "integrator",
    "film",
    "sampler",
    "rfilter",
    "texture",
    "medium",
    "phase",
    "volume",
];

/// The most plugin elements ([`PLUGIN_TAGS`]) a scene may have: every one that is not audited
/// is listed in the report and its summary, and a Mitsuba scene that mfh audits names a few
/// hundred (the 1 MiB size limit held 61 000 empty `<shape/>`s, a 3 MB not-audited list).
pub const MAX_PLUGINS: usize = 10_000;

/// BSDFs that only wrap others.
const WRAPPERS: &[&str] = &["twosided", "blendbsdf", "mask", "bumpmap", "normalmap"];

/// The deepest nesting of elements a scene may have. Mitsuba scenes nest a handful of levels;
/// the XML parser recurses once per level, and ~20 000 levels (well under the 1 MiB size
/// limit) overflowed its stack (exit 134) before this bound.
pub const MAX_XML_DEPTH: usize = 128;

/// Where (line, column, 1-based) the nesting of elements first exceeds `limit`, scanning the
/// text without building a tree: comments, CDATA, processing instructions and declarations
/// are skipped, quoted attribute values may hold `>`, `<x/>` does not nest. Malformed text
/// is left to the parser's own error.
fn too_deep(text: &str, limit: usize) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let skip_to = |from: usize, end: &[u8]| {
        b[from..]
            .windows(end.len())
            .position(|w| w == end)
            .map_or(b.len(), |p| from + p + end.len())
    };
    let mut depth = 0usize;
    let mut i = 0;
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &b[i..];
        if rest.starts_with(b"<!--") {
            i = skip_to(i + 4, b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_to(i + 9, b"]]>");
        } else if rest.starts_with(b"<?") {
            i = skip_to(i + 2, b"?>");
        } else if rest.starts_with(b"<!") {
            i = skip_to(i + 2, b">");
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            i = skip_to(i + 2, b">");
        } else {
            let start = i;
            let mut quote = None;
            let mut j = i + 1;
            while j < b.len() {
                match (quote, b[j]) {
                    (None, q @ (b'"' | b'\'')) => quote = Some(q),
                    (Some(q), c) if c == q => quote = None,
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            if j < b.len() && b[j - 1] != b'/' {
                depth += 1;
                if depth > limit {
                    let line = 1 + b[..start].iter().filter(|&&c| c == b'\n').count();
                    let column = start
                        - b[..start]
                            .iter()
                            .rposition(|&c| c == b'\n')
                            .map_or(0, |p| p + 1)
                        + 1;
                    return Some((line, column));
                }
            }
            i = j + 1;
        }
    }
    None
}

/// Parses a Mitsuba 3 XML scene; `origin` names the file in errors and the scene.
pub fn parse(text: &str, origin: &str) -> Result<Scene, SceneError> {
    if let Some((line, column)) = too_deep(text, MAX_XML_DEPTH) {
        return Err(SceneError::Syntax {
            origin: origin.to_string(),
            line,
            column,
            message: format!(
                "elements nested more than {MAX_XML_DEPTH} deep (a Mitsuba scene nests a few \
                 levels; the XML parser recurses per level)"
            ),
        });
    }
    let doc = Document::parse(text).map_err(|e| {
        let pos = e.pos();
        SceneError::Syntax {
            origin: origin.to_string(),
            line: pos.row as usize,
            column: pos.col as usize,
            message: format!("malformed XML: {e}"),
        }
    })?;
    let mut reader = Reader {
        positions: position::Positions::new(text),
        origin,
        defaults: BTreeMap::new(),
        ids: BTreeSet::new(),
        materials: Vec::new(),
        not_audited: Vec::new(),
    };
    let root = doc.root_element();
    if root.tag_name().name() != "scene" {
        return Err(reader.error(
            root,
            format!(
                "the root element is <{}>, a Mitsuba scene's is <scene>",
                root.tag_name().name()
            ),
        ));
    }
    let plugins = root
        .descendants()
        .filter(|n| n.is_element() && PLUGIN_TAGS.contains(&n.tag_name().name()))
        .count();
    if plugins > MAX_PLUGINS {
        return Err(reader.error(
            root,
            format!(
                "{plugins} plugin elements (<shape>, <bsdf>, <emitter>, …) exceed the limit of \
                 {MAX_PLUGINS} (each one not audited is listed in the report)"
            ),
        ));
    }
    for node in root.descendants().filter(Node::is_element) {
        match node.tag_name().name() {
            "include" => {
                return Err(reader.error(
                    node,
                    format!(
                        "<include filename=\"{}\"> is refused: mfh reads one self-contained scene file (inline the included file)",
                        node.attribute("filename").unwrap_or("")
                    ),
                ))
            }
            "default" => {
                let (Some(name), Some(value)) = (node.attribute("name"), node.attribute("value"))
                else {
                    return Err(reader.error(node, "<default> needs `name` and `value`".into()));
                };
                reader.defaults.insert(name.to_string(), value.to_string());
            }
            _ => {}
        }
        if let (false, Some(id)) = (node.has_tag_name("ref"), node.attribute("id")) {
            reader.ids.insert(id.to_string());
        }
    }
    reader.walk(root, None)?;
    let name = std::path::Path::new(origin)
        .file_name()
        .map_or_else(|| origin.to_string(), |n| n.to_string_lossy().into_owned());
    let scene = Scene {
        name: format!("Mitsuba scene {name}"),
        materials: reader.materials,
        filtering: Default::default(),
        lighting: Default::default(),
        incidence: Default::default(),
        not_audited: reader.not_audited,
    };
    scene.validate(origin)
}

/// The walk over one document.
struct Reader<'a, 'input> {
    positions: position::Positions<'input>,
    origin: &'a str,
    defaults: BTreeMap<String, String>,
    ids: BTreeSet<String>,
    materials: Vec<Material>,
    not_audited: Vec<NotAudited>,
}

/// A property of a plugin as written.
enum Prop {
    /// A number.
    Float(f64),
    /// A string.
    Str(String),
    /// A boolean.
    Bool(bool),
    /// Anything that varies over the surface or is not a scalar: a texture, a ref, a colour.
    Varying(String),
}

impl<'input> Reader<'_, 'input> {
    fn error(&self, node: Node, message: String) -> SceneError {
        let (line, column) = self.positions.at(node.range().start);
        SceneError::Syntax {
            origin: self.origin.to_string(),
            line,
            column,
            message,
        }
    }

    /// An attribute with `$name` parameters substituted from the `<default>`s.
    fn attr(&self, node: Node, key: &str) -> Result<Option<String>, SceneError> {
        let Some(raw) = node.attribute(key) else {
            return Ok(None);
        };
        let mut out = String::new();
        let mut rest = raw;
        while let Some(at) = rest.find('$') {
            out.push_str(&rest[..at]);
            let tail = &rest[at + 1..];
            let len = tail
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(tail.len());
            let name = &tail[..len];
            match self.defaults.get(name) {
                Some(v) if !name.is_empty() => out.push_str(v),
                _ => {
                    return Err(self.error(
                        node,
                        format!(
                            "attribute {key}=\"{raw}\" uses the parameter `${name}`, which no <default name=\"{name}\"> defines"
                        ),
                    ))
                }
            }
            rest = &tail[len..];
        }
        out.push_str(rest);
        Ok(Some(out))
    }

    /// The display id of a plugin: its `id`, else `<type>@line:column`.
    fn id_of(&self, node: Node, kind: &str) -> Result<String, SceneError> {
        Ok(match self.attr(node, "id")? {
            Some(id) => id,
            None => {
                let (line, column) = self.positions.at(node.range().start);
                format!("{kind}@{line}:{column}")
            }
        })
    }

    /// Walks the children of `node`: BSDFs become materials, other plugins are listed.
    fn walk(&mut self, node: Node<'_, 'input>, parent: Option<&str>) -> Result<(), SceneError> {
        for child in node.children().filter(Node::is_element) {
            let tag = child.tag_name().name();
            if tag == "ref" {
                let id = self.attr(child, "id")?.unwrap_or_default();
                if !self.ids.contains(&id) {
                    return Err(self.error(
                        child,
                        format!("<ref id=\"{id}\"> names no element of the scene"),
                    ));
                }
                continue; // the named element is read where it is defined, once
            }
            if !PLUGIN_TAGS.contains(&tag) {
                continue; // a property, a transform, a <default>
            }
            let kind = self.attr(child, "type")?.unwrap_or_default();
            if tag == "bsdf" {
                self.bsdf(child, &kind, parent)?;
            } else if child.attribute("name").is_some() && parent.is_some() {
                // A texture or other plugin given as a property of a BSDF: the BSDF says what
                // it does with it.
            } else {
                let id = self.id_of(child, &kind)?;
                self.not_audited.push(NotAudited {
                    plugin: format!("{tag} {kind}"),
                    id,
                    reason: "is not a BSDF".to_string(),
                });
                self.walk(child, None)?;
            }
        }
        Ok(())
    }

    fn bsdf(
        &mut self,
        node: Node<'_, 'input>,
        kind: &str,
        parent: Option<&str>,
    ) -> Result<(), SceneError> {
        let id = self.id_of(node, kind)?;
        let name = match parent {
            Some(p) => format!("{p}/{id}"),
            None => id.clone(),
        };
        match kind {
            k if WRAPPERS.contains(&k) => self.walk(node, Some(&name)),
            "roughconductor" | "roughdielectric" | "roughplastic" => {
                self.rough(node, kind, &name, &id)
            }
            "principled" | "principledthin" => self.principled(node, kind, &name, &id),
            _ => {
                self.not_audited.push(NotAudited {
                    plugin: kind.to_string(),
                    id: name,
                    reason: "has no microfacet model".to_string(),
                });
                Ok(())
            }
        }
    }

    /// The property `name` of a plugin, if written.
    fn prop(&self, node: Node, name: &str) -> Result<Option<Prop>, SceneError> {
        let Some(child) = node
            .children()
            .filter(Node::is_element)
            .find(|c| c.attribute("name") == Some(name))
        else {
            return Ok(None);
        };
        let tag = child.tag_name().name();
        let value = self.attr(child, "value")?;
        let need = |v: Option<String>| {
            v.ok_or_else(|| self.error(child, format!("<{tag} name=\"{name}\"> has no value")))
        };
        Ok(Some(match tag {
            "float" | "integer" => {
                let text = need(value)?;
                let x: f64 = text.trim().parse().map_err(|_| {
                    self.error(
                        child,
                        format!("<{tag} name=\"{name}\" value=\"{text}\">: not a number"),
                    )
                })?;
                Prop::Float(x)
            }
            "string" => Prop::Str(need(value)?),
            "boolean" => {
                let text = need(value)?;
                match text.trim().to_ascii_lowercase().as_str() {
                    "true" => Prop::Bool(true),
                    "false" => Prop::Bool(false),
                    _ => {
                        return Err(self.error(
                            child,
                            format!(
                                "<boolean name=\"{name}\" value=\"{text}\">: not true or false"
                            ),
                        ))
                    }
                }
            }
            other => Prop::Varying(match self.attr(child, "type")? {
                Some(t) => format!("a {other} ({t})"),
                None => format!("a {other}"),
            }),
        }))
    }

    /// A scalar float property with its default; `Err(reason)` inside `Ok` when it varies.
    fn float(
        &self,
        node: Node,
        name: &str,
        default: f64,
    ) -> Result<Result<f64, String>, SceneError> {
        Ok(match self.prop(node, name)? {
            None => Ok(default),
            Some(Prop::Float(x)) => Ok(x),
            Some(Prop::Varying(what)) => Err(format!(
                "has no fixed roughness: `{name}` is {what} (mfh audits a fixed roughness: give a <float>)"
            )),
            Some(_) => {
                return Err(self.error(node, format!("`{name}` must be a <float>")));
            }
        })
    }

    fn not_audited(&mut self, plugin: &str, id: &str, reason: String) {
        self.not_audited.push(NotAudited {
            plugin: plugin.to_string(),
            id: id.to_string(),
            reason,
        });
    }

    /// roughconductor, roughdielectric, roughplastic.
    fn rough(&mut self, node: Node, kind: &str, name: &str, _id: &str) -> Result<(), SceneError> {
        let distribution = match self.prop(node, "distribution")? {
            None => "beckmann".to_string(),
            Some(Prop::Str(s)) => s,
            Some(_) => return Err(self.error(node, "`distribution` must be a <string>".into())),
        };
        if distribution != "beckmann" && distribution != "ggx" {
            return Err(self.error(
                node,
                format!("{kind} `{name}`: distribution `{distribution}` is neither beckmann nor ggx (Mitsuba 3 has these two)"),
            ));
        }
        let sample_visible = match self.prop(node, "sample_visible")? {
            None => true,
            Some(Prop::Bool(b)) => b,
            Some(_) => return Err(self.error(node, "`sample_visible` must be a <boolean>".into())),
        };
        let anisotropic =
            self.prop(node, "alpha_u")?.is_some() || self.prop(node, "alpha_v")?.is_some();
        if anisotropic && kind == "roughplastic" {
            return Err(self.error(
                node,
                format!("roughplastic `{name}` is isotropic: Mitsuba reads `alpha`, not `alpha_u`/`alpha_v`"),
            ));
        }
        let (ax, ay) = if anisotropic {
            if self.prop(node, "alpha")?.is_some() {
                return Err(self.error(
                    node,
                    format!(
                        "{kind} `{name}`: give either `alpha` or `alpha_u` and `alpha_v`, not both"
                    ),
                ));
            }
            let (Some(_), Some(_)) = (self.prop(node, "alpha_u")?, self.prop(node, "alpha_v")?)
            else {
                return Err(self.error(
                    node,
                    format!("{kind} `{name}`: `alpha_u` and `alpha_v` go together"),
                ));
            };
            let u = self.float(node, "alpha_u", 0.1)?;
            let v = self.float(node, "alpha_v", 0.1)?;
            match (u, v) {
                (Ok(u), Ok(v)) => (u, v),
                (Err(r), _) | (_, Err(r)) => {
                    self.not_audited(kind, name, r);
                    return Ok(());
                }
            }
        } else {
            match self.float(node, "alpha", 0.1)? {
                Ok(a) => (a, a),
                Err(r) => {
                    self.not_audited(kind, name, r);
                    return Ok(());
                }
            }
        };
        let model = microfacet_spec(&distribution, ax, ay);
        let sampling = if sample_visible {
            Sampling::VisibleNormals
        } else {
            Sampling::Normals
        };
        let bsdf = match kind {
            "roughplastic" => None,
            _ => Some(self.rough_bsdf(node, kind, name, &model, sample_visible)?),
        };
        self.materials.push(Material {
            name: name.to_string(),
            model: Some(model),
            bsdf,
            masking: Some(Masking::Uncorrelated),
            sampling: Some(sampling),
        });
        Ok(())
    }

    /// principled and principledthin: the GGX main lobe, and principled's GTR1 clearcoat.
    fn principled(
        &mut self,
        node: Node,
        kind: &str,
        name: &str,
        _id: &str,
    ) -> Result<(), SceneError> {
        let roughness = match self.float(node, "roughness", 0.5)? {
            Ok(r) => r,
            Err(r) => {
                self.not_audited(kind, name, r);
                return Ok(());
            }
        };
        // principledhelpers.h `get_flag`: anisotropy is on when the property is present and
        // not the float 0.
        let anisotropic = match self.float(node, "anisotropic", 0.0)? {
            Ok(a) => a,
            Err(r) => {
                self.not_audited(kind, name, r);
                return Ok(());
            }
        };
        let r2 = roughness * roughness;
        let (ax, ay) = if anisotropic == 0.0 {
            (r2.max(1e-3), r2.max(1e-3))
        } else {
            let aspect = (1.0 - 0.9 * anisotropic).sqrt();
            ((r2 / aspect).max(1e-3), (r2 * aspect).max(1e-3))
        };
        if !(ax.is_finite() && ay.is_finite()) {
            return Err(self.error(
                node,
                format!("{kind} `{name}`: roughness {roughness} and anisotropic {anisotropic} give α = ({ax}, {ay}); anisotropic must be in [0, 1]"),
            ));
        }
        self.materials.push(Material {
            name: name.to_string(),
            model: Some(microfacet_spec("ggx", ax, ay)),
            bsdf: None,
            masking: Some(Masking::Uncorrelated),
            sampling: Some(Sampling::VisibleNormals),
        });
        if kind == "principled" {
            let clearcoat = self.float(node, "clearcoat", 0.0)?;
            let on = !matches!(clearcoat, Ok(c) if c == 0.0);
            if on {
                match self.float(node, "clearcoat_gloss", 0.0)? {
                    Ok(gloss) => {
                        let alpha = 0.1 + (0.001 - 0.1) * gloss;
                        let cc = format!("{name}/clearcoat");
                        self.materials.push(Material {
                            name: cc.clone(),
                            model: Some(ModelSpec::Gtr(mfh_reference::ndf::gtr::GtrSpec {
                                gamma: 1.0,
                                alpha,
                            })),
                            bsdf: None,
                            masking: None,
                            sampling: Some(Sampling::Normals),
                        });
                        self.not_audited(
                            "principled clearcoat masking",
                            &cc,
                            "masks with a GGX G1 at α = 0.25 (Burley 2012), not a Smith G of its GTR1 NDF: no closed form of the source documents to check it against".to_string(),
                        );
                    }
                    Err(r) => {
                        self.not_audited("principled clearcoat", &format!("{name}/clearcoat"), r)
                    }
                }
            }
        }
        Ok(())
    }
}

/// The spec of a Beckmann or GGX NDF with Mitsuba's α clamp; isotropic when α_u = α_v.
fn microfacet_spec(distribution: &str, alpha_u: f64, alpha_v: f64) -> ModelSpec {
    let clamp = |a: f64| {
        if a.is_nan() {
            a
        } else {
            a.max(MITSUBA_ALPHA_MIN)
        }
    };
    let (u, v) = (clamp(alpha_u), clamp(alpha_v));
    let (alpha, alpha_x, alpha_y) = if u == v {
        (Some(u), None, None)
    } else {
        (None, Some(u), Some(v))
    };
    if distribution == "ggx" {
        ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
            alpha,
            alpha_x,
            alpha_y,
        })
    } else {
        ModelSpec::Beckmann(mfh_reference::ndf::beckmann::BeckmannSpec {
            alpha,
            alpha_x,
            alpha_y,
        })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn nesting_beyond_the_bound_is_a_syntax_error_not_a_stack_overflow() {
        let deep = format!(
            "<scene version=\"3.0.0\">{}{}</scene>",
            "<a>".repeat(20_000),
            "</a>".repeat(20_000)
        );
        let e = parse(&deep, "deep.xml").unwrap_err().to_string();
        assert!(
            e.contains("deep.xml:1:") && e.contains("nested more than 128"),
            "{e}"
        );
        let ok = format!(
            "<!-- <a><a> --><scene a='>'>{}<b/>{}</scene>",
            "<c>".repeat(100),
            "</c>".repeat(100)
        );
        assert_eq!(too_deep(&ok, MAX_XML_DEPTH), None);
        assert_eq!(too_deep("<a>\n <b>", 1), Some((2, 2)));
    }

    use super::*;
    use crate::scene::MaterialBsdf;
    use mfh_reference::bsdf::{BsdfSpec, ConductorSpec, FresnelModel, Sampling as BsdfSampling};

    fn scene(body: &str) -> Result<Scene, SceneError> {
        parse(
            &format!("<scene version=\"3.0.0\">\n{body}\n</scene>"),
            "t.xml",
        )
    }

    #[test]
    fn defaults_follow_mitsuba() {
        let s = scene(r#"<bsdf type="roughconductor" id="metal"/>"#).unwrap();
        assert_eq!(s.materials.len(), 1);
        let m = &s.materials[0];
        assert_eq!(m.name, "metal");
        let beckmann = ModelSpec::Beckmann(mfh_reference::ndf::beckmann::BeckmannSpec {
            alpha: Some(0.1),
            alpha_x: None,
            alpha_y: None,
        });
        assert_eq!(m.model, Some(beckmann.clone()));
        assert_eq!(m.masking, Some(Masking::Uncorrelated));
        assert_eq!(m.sampling, Some(Sampling::VisibleNormals));
        // The reference BSDF: the same NDF, the default index, Mitsuba's separable masking.
        let (n, k) = DEFAULT_CONDUCTOR_NK;
        assert_eq!(
            m.bsdf.as_ref().map(MaterialBsdf::spec),
            Some(BsdfSpec::Conductor(ConductorSpec {
                n,
                k,
                fresnel: FresnelModel::Exact,
                ndf: beckmann,
                masking: Masking::Uncorrelated,
                sampling: BsdfSampling::VisibleNormals,
                two_sided: false,
            }))
        );
    }

    #[test]
    fn rough_dielectric_and_conductor_name_their_reference_bsdf() {
        let s = scene(
            r#"<bsdf type="roughdielectric" id="glass"><string name="distribution" value="ggx"/>
               <float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.3"/>
               <float name="int_ior" value="1.8"/><float name="ext_ior" value="1.2"/>
               <boolean name="sample_visible" value="false"/></bsdf>
               <bsdf type="roughdielectric" id="bk7"/>
               <bsdf type="roughconductor" id="metal"><float name="eta" value="1.1"/>
               <spectrum name="k" value="400:2, 700:3"/></bsdf>
               <bsdf type="roughplastic" id="plastic"/>"#,
        )
        .unwrap();
        match s.materials[0].bsdf.as_ref().map(MaterialBsdf::spec) {
            Some(BsdfSpec::Dielectric(d)) => {
                assert!((d.eta - 1.5).abs() < 1e-15, "{}", d.eta);
                assert_eq!(d.sampling, BsdfSampling::Normals);
                assert_eq!(d.masking, Masking::Uncorrelated);
                assert_eq!(Some(&d.ndf), s.materials[0].model.as_ref());
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            s.materials[1].bsdf.as_ref().and_then(|b| b.spec().eta()),
            Some(MITSUBA_BK7_IOR / MITSUBA_AIR_IOR)
        );
        match s.materials[2].bsdf.as_ref().map(MaterialBsdf::spec) {
            Some(BsdfSpec::Conductor(c)) => {
                assert_eq!((c.n, c.k), (1.1, DEFAULT_CONDUCTOR_NK.1));
            }
            other => panic!("{other:?}"),
        }
        assert!(
            s.not_audited[0].to_string().contains("`k`"),
            "{:?}",
            s.not_audited
        );
        assert_eq!(
            s.materials[3].bsdf, None,
            "roughplastic is no reference BSDF"
        );
    }

    #[test]
    fn bad_bsdf_values_name_the_mitsuba_property() {
        for (xml, needles) in [
            (
                r#"<bsdf type="roughdielectric"><float name="int_ior" value="20"/></bsdf>"#,
                &["t.xml:2:", "int_ior/ext_ior", "eta", "10"][..],
            ),
            (
                r#"<bsdf type="roughdielectric"><float name="int_ior" value="1.0002"/><float name="ext_ior" value="1.0002"/></bsdf>"#,
                &["int_ior/ext_ior"],
            ),
            (
                r#"<bsdf type="roughdielectric"><string name="int_ior" value="bk7"/></bsdf>"#,
                &["int_ior", "bk7", "<float>"],
            ),
            (
                r#"<bsdf type="roughconductor"><float name="eta" value="-1"/></bsdf>"#,
                &["roughconductor", "eta", "1e-3"],
            ),
            (
                r#"<bsdf type="roughconductor"><float name="k" value="1000"/></bsdf>"#,
                &["k", "100"],
            ),
        ] {
            let e = scene(xml).unwrap_err().to_string();
            for n in needles {
                assert!(e.contains(n), "{xml}: {e} lacks {n}");
            }
        }
    }

    #[test]
    fn principled_maps_roughness_and_anisotropy() {
        let s = scene(
            r#"<bsdf type="principled" id="p"><float name="roughness" value="0.6"/>
               <float name="anisotropic" value="0.5"/><float name="clearcoat" value="1"/>
               <float name="clearcoat_gloss" value="0.5"/></bsdf>"#,
        )
        .unwrap();
        let aspect = (1.0f64 - 0.45).sqrt();
        match &s.materials[0].model {
            Some(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
                alpha_x: Some(x),
                alpha_y: Some(y),
                ..
            })) => {
                assert!((x - 0.36 / aspect).abs() < 1e-15 && (y - 0.36 * aspect).abs() < 1e-15);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            s.materials[1].model,
            Some(ModelSpec::Gtr(mfh_reference::ndf::gtr::GtrSpec {
                gamma: 1.0,
                alpha: 0.1 - 0.099 * 0.5
            }))
        );
        assert_eq!(s.not_audited.len(), 1);
    }

    #[test]
    fn parameters_substitute_and_errors_have_positions() {
        let s = scene(
            r#"<default name="a" value="0.25"/>
               <bsdf type="roughconductor"><float name="alpha" value="$a"/>
               <string name="distribution" value="ggx"/></bsdf>"#,
        )
        .unwrap();
        assert_eq!(s.materials[0].name, "roughconductor@3:16");
        assert!(matches!(
            s.materials[0].model,
            Some(ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
                alpha: Some(a),
                ..
            })) if a == 0.25
        ));
        let e = scene(r#"<bsdf type="roughconductor"><float name="alpha" value="$b"/></bsdf>"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.xml:2:29:") && e.contains("$b"), "{e}");
        let e = scene("  <include filename=\"other.xml\"/>")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.xml:2:3:") && e.contains("refused"), "{e}");
        let e = scene(
            r#"<bsdf type="roughconductor"><string name="distribution" value="phong"/></bsdf>"#,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("phong"), "{e}");
        let e = scene(r#"<shape type="obj"><ref id="nowhere"/></shape>"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("nowhere") && e.starts_with("t.xml:2:"), "{e}");
    }

    #[test]
    fn a_textured_roughness_is_not_audited_with_its_reason() {
        let s = scene(
            r#"<bsdf type="roughplastic" id="tex"><texture name="alpha" type="bitmap"/></bsdf>
               <bsdf type="roughplastic" id="ok"/>"#,
        )
        .unwrap();
        assert_eq!(s.materials.len(), 1);
        assert_eq!(s.not_audited[0].id, "tex");
        assert!(s.not_audited[0].reason.contains("texture (bitmap)"));
    }
}
