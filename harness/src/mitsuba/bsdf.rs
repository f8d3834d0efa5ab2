//! The reference BSDF a Mitsuba 3 `roughconductor` or `roughdielectric` names: its
//! relative index or complex index, Mitsuba's separable masking and its sampling, as a
//! [`BsdfSpec`] whose BSDF checks are planned beside the NDF's (see the parent module's table).

use super::{Prop, Reader, DEFAULT_CONDUCTOR_NK, MITSUBA_AIR_IOR, MITSUBA_BK7_IOR};
use crate::scene::{MaterialBsdf, SceneError};
use mfh_reference::bsdf::{
    BsdfSpec, ConductorSpec, DielectricSpec, FresnelModel, Sampling as BsdfSampling, Transport,
};
use mfh_reference::{Masking, ModelSpec};
use roxmltree::Node;

impl Reader<'_, '_> {
    /// The reference BSDF of a roughconductor or roughdielectric with the NDF `ndf`:
    /// Mitsuba's separable (uncorrelated) masking, its visible-normal or normal sampling, the
    /// exact Fresnel, radiance transport. A roughdielectric's η = `int_ior`/`ext_ior` (floats;
    /// Mitsuba's defaults bk7 and air as numbers); a roughconductor's complex index `eta` + i`k`
    /// (floats; [`DEFAULT_CONDUCTOR_NK`] where absent or spectral, which is then listed as not
    /// audited). An invalid value is an error naming the Mitsuba property and the limit.
    pub(super) fn rough_bsdf(
        &mut self,
        node: Node,
        kind: &str,
        name: &str,
        ndf: &ModelSpec,
        sample_visible: bool,
    ) -> Result<MaterialBsdf, SceneError> {
        let sampling = if sample_visible {
            BsdfSampling::VisibleNormals
        } else {
            BsdfSampling::Normals
        };
        let spec = if kind == "roughdielectric" {
            let int_ior = self.ior(node, kind, name, "int_ior", MITSUBA_BK7_IOR)?;
            let ext_ior = self.ior(node, kind, name, "ext_ior", MITSUBA_AIR_IOR)?;
            BsdfSpec::Dielectric(DielectricSpec {
                eta: int_ior / ext_ior,
                ndf: ndf.clone(),
                masking: Masking::Uncorrelated,
                sampling,
                transport: Transport::Radiance,
            })
        } else {
            let (n0, k0) = DEFAULT_CONDUCTOR_NK;
            if let Some(Prop::Str(material)) = self.prop(node, "material")? {
                if self.prop(node, "eta")?.is_none() {
                    self.not_audited(
                        &format!("{kind} material"),
                        name,
                        format!(
                            "the named material `{material}` is not read (mfh has no table of \
                             Mitsuba's spectral indices): the BSDF is audited with n = {n0}, \
                             k = {k0}"
                        ),
                    );
                }
            }
            let mut index = |property: &str, default: f64| -> Result<f64, SceneError> {
                Ok(match self.prop(node, property)? {
                    None => default,
                    Some(Prop::Float(x)) => x,
                    Some(_) => {
                        self.not_audited(
                            &format!("{kind} {property}"),
                            name,
                            format!(
                                "`{property}` is not a <float> (spectral or named): the BSDF is \
                                 audited with the default {property} = {default}"
                            ),
                        );
                        default
                    }
                })
            };
            let n = index("eta", n0)?;
            let k = index("k", k0)?;
            BsdfSpec::Conductor(ConductorSpec {
                n,
                k,
                fresnel: FresnelModel::Exact,
                ndf: ndf.clone(),
                masking: Masking::Uncorrelated,
                sampling,
                two_sided: false,
            })
        };
        if let Err(e) = spec.validate() {
            let property = match e.field() {
                "eta" => "int_ior/ext_ior",
                "n" => "eta",
                "ndf" => "alpha",
                other => other,
            };
            return Err(self.error(
                node,
                format!(
                    "{kind} `{name}`: {property}: {}",
                    crate::messages::compact_numbers(&e.to_string())
                ),
            ));
        }
        Ok(MaterialBsdf::of(spec))
    }

    /// The index of refraction `property` of a roughdielectric: a <float>, or `default` when
    /// absent. Mitsuba's named IORs (`<string value="bk7">`) are refused: mfh has no table.
    fn ior(
        &self,
        node: Node,
        kind: &str,
        name: &str,
        property: &str,
        default: f64,
    ) -> Result<f64, SceneError> {
        match self.prop(node, property)? {
            None => Ok(default),
            Some(Prop::Float(x)) => Ok(x),
            Some(Prop::Str(s)) => Err(self.error(
                node,
                format!(
                    "{kind} `{name}`: {property}: the named IOR \"{s}\" is not read (mfh has no \
                     table of Mitsuba's named IORs): give the index as a <float>"
                ),
            )),
            Some(_) => Err(self.error(
                node,
                format!("{kind} `{name}`: {property} must be a <float>"),
            )),
        }
    }
}
