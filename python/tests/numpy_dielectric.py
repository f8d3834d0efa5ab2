"""A rough dielectric BSDF vectorized with numpy, float64: examples/external/dielectric.py's
model (Walter, Marschner, Li & Torrance 2007 over an isotropic GGX interface, exact Fresnel,
height-correlated G2 in both lobes, visible-normal sampling after Heitz 2018, radiance
transport), the same formulas written over arrays: the reference BSDF
``{"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}``.

    model = Dielectric(alpha=0.3, eta=1.5)        # defect="refraction_jacobian": the classic bug
    mfh.audit_bsdf(eval=model.eval, pdf=model.pdf, sample=model.sample, eta=model.eta)

The formulas and their equation numbers are in dielectric.py's docstring.
"""
import numpy as np

DEFECTS = {
    # the pdf of refracted directions without Walter's Jacobian (eq 17): bsdf.chi2 sees it
    "refraction_jacobian": "bsdf.chi2",
}


def _fresnel(c, eta):
    """(reflectance, transmittance, cos_t) at |cos| c, eta = eta_t/eta_i (Walter eq 22, in
    forms without cancellation)."""
    c = np.minimum(np.abs(c), 1.0)
    e2 = eta * eta
    em1 = (eta - 1.0) * (eta + 1.0)
    g2 = em1 + c * c
    tir = ~(g2 > 0.0)
    g = np.sqrt(np.where(tir, 1.0, g2))
    s = c + g
    p = e2 * c + g
    rs = -em1 / (s * s)
    rp = em1 * ((e2 + 1.0) * c * c - 1.0) / (p * p)
    r = 0.5 * (rs * rs + rp * rp)
    t = 2.0 * c * g * (1.0 / (s * s) + e2 / (p * p))
    return (np.where(tir, 1.0, np.minimum(r, 1.0)),
            np.where(tir, 0.0, np.clip(t, 0.0, 1.0)),
            np.where(tir, 0.0, np.minimum(g / eta, 1.0)))


class Dielectric:
    def __init__(self, alpha=0.3, eta=1.5, defect=None):
        if defect not in (None,) + tuple(DEFECTS):
            raise ValueError("defect %r is not one of %s" % (defect, sorted(DEFECTS)))
        self.alpha, self.eta, self.defect = float(alpha), float(eta), defect
        self.a2 = self.alpha * self.alpha

    # --- the NDF it is built on ----------------------------------------------------------

    def _lam(self, x, y, z):
        """Smith Lambda of GGX at w+ (depends on |z| only), z != 0."""
        t = self.a2 * (x * x + y * y) / (z * z)
        return np.where(t == 0.0, 0.0, t / (2.0 * (1.0 + np.sqrt(1.0 + t))))

    def _d(self, mx, my, mz):
        z2 = mz * mz
        s = 1.0 + (mx * mx + my * my) / (self.a2 * z2)
        return 1.0 / (np.pi * self.a2 * z2 * z2 * s * s)

    def d(self, m):
        """D(m), 0 below the horizon."""
        with np.errstate(all="ignore"):
            return np.where(m[:, 2] > 0.0, self._d(m[:, 0], m[:, 1], m[:, 2]), 0.0)

    def lambda_(self, w):
        """Lambda(w), Lambda(-w) = -1 - Lambda(w) below; infinite at grazing."""
        x, y, z = w[:, 0], w[:, 1], w[:, 2]
        with np.errstate(all="ignore"):
            up = self._lam(x, y, z)
        up = np.where(z == 0.0, np.where(x * x + y * y > 0.0, np.inf, 0.0), up)
        return np.where(z < 0.0, -1.0 - up, up)

    def _pdf_m(self, wx, wy, wz, mx, my, mz, d, lam_w):
        """Density of the visible normal m at w+."""
        flip = np.where(wz < 0.0, -1.0, 1.0)
        wx, wy, wz = wx * flip, wy * flip, wz * flip
        c = wx * mx + wy * my + wz * mz
        ok = (wz > 0.0) & (mz > 0.0) & (c > 0.0)
        return np.where(ok, c * d / (wz * (1.0 + lam_w)), 0.0)

    # --- the BSDF ------------------------------------------------------------------------

    def evaluate(self, wi, wo):
        """(eval, pdf) at each (wi, wo)."""
        eta = self.eta
        ix, iy, ci = wi[:, 0], wi[:, 1], wi[:, 2]
        ox, oy, co = wo[:, 0], wo[:, 1], wo[:, 2]
        with np.errstate(all="ignore"):
            valid = (ci != 0.0) & (co != 0.0) & np.isfinite(ix + iy + ci + ox + oy + co)
            lam_i = self._lam(ix, iy, ci)
            g = 1.0 / (1.0 + lam_i + self._lam(ox, oy, co))
            # reflection (eq 13, 20, 14)
            hx, hy, hz = ix + ox, iy + oy, ci + co
            length = np.sqrt(hx * hx + hy * hy + hz * hz)
            s = np.where(ci > 0.0, 1.0, -1.0) / length
            mx, my, mz = s * hx, s * hy, s * hz
            cim = ix * mx + iy * my + ci * mz
            com = ox * mx + oy * my + co * mz
            ok_r = valid & (ci * co > 0.0) & (length > 0.0) & (mz > 0.0) & (cim * ci > 0.0) \
                & (com * co > 0.0)
            c = 0.5 * length
            f = _fresnel(c, np.where(ci > 0.0, eta, 1.0 / eta))[0]
            d = self._d(mx, my, mz)
            value_r = f * g * d / (4.0 * np.abs(ci))
            pdf_r = f * self._pdf_m(ix, iy, ci, mx, my, mz, d, lam_i) / (4.0 * c)
            # refraction (eq 16, 21, 17)
            eta_i = np.where(ci > 0.0, 1.0, eta)
            eta_o = np.where(co > 0.0, 1.0, eta)
            vx, vy, vz = eta_i * ix + eta_o * ox, eta_i * iy + eta_o * oy, eta_i * ci + eta_o * co
            len2 = vx * vx + vy * vy + vz * vz
            length = np.sqrt(len2)
            s = np.where(vz > 0.0, 1.0, -1.0) / length
            mx, my, mz = s * vx, s * vy, s * vz
            cim = ix * mx + iy * my + ci * mz
            com = ox * mx + oy * my + co * mz
            t = np.where(eta_i < eta_o, _fresnel(cim, eta_o / eta_i)[1],
                         _fresnel(com, eta_i / eta_o)[1])
            ok_t = valid & (ci * co < 0.0) & (length > 0.0) & (mz > 0.0) & (cim * ci > 0.0) \
                & (com * co > 0.0) & (t > 0.0)
            d = self._d(mx, my, mz)
            jacobian = eta_o * eta_o * np.abs(com) / len2
            ratio = eta_i / eta_o
            value_t = np.abs(cim) * t * g * d * jacobian / np.abs(ci) * (ratio * ratio)
            pdf_t = t * self._pdf_m(ix, iy, ci, mx, my, mz, d, lam_i) \
                * (1.0 if self.defect == "refraction_jacobian" else jacobian)
            value = np.where(ok_r, value_r, np.where(ok_t, value_t, 0.0))
            pdf = np.where(ok_r, pdf_r, np.where(ok_t, pdf_t, 0.0))
        return (np.where(np.isfinite(value), value, 0.0), np.where(np.isfinite(pdf), pdf, 0.0))

    def eval(self, wi, wo):
        return self.evaluate(wi, wo)[0]

    def pdf(self, wi, wo):
        return self.evaluate(wi, wo)[1]

    def sample(self, wi, u):
        """(wo, pdf, weight): m from GGX's visible normals at wi+ (Heitz 2018) by u1, u2;
        u0 < F reflects, else refracts; failed samples answer pdf 0."""
        a, eta = self.alpha, self.eta
        ix, iy, ci = wi[:, 0], wi[:, 1], wi[:, 2]
        with np.errstate(all="ignore"):
            valid = (ci != 0.0) & np.isfinite(ix + iy + ci)
            flip = np.where(ci < 0.0, -1.0, 1.0)
            px, py, pz = ix * flip, iy * flip, ci * flip
            vx, vy, vz = a * px, a * py, pz
            n = np.sqrt(vx * vx + vy * vy + vz * vz)
            vx, vy, vz = vx / n, vy / n, vz / n
            l2 = vx * vx + vy * vy
            il = 1.0 / np.sqrt(l2)
            t1x = np.where(l2 > 0.0, -vy * il, 1.0)
            t1y = np.where(l2 > 0.0, vx * il, 0.0)
            t2x, t2y, t2z = -vz * t1y, vz * t1x, vx * t1y - vy * t1x
            s = 0.5 * (1.0 + vz)
            r = np.sqrt(u[:, 1])
            phi = 2.0 * np.pi * u[:, 2]
            pa = r * np.cos(phi)
            pb = (1.0 - s) * np.sqrt(np.maximum(0.0, 1.0 - pa * pa)) + s * r * np.sin(phi)
            lift = np.sqrt(np.maximum(0.0, 1.0 - pa * pa - pb * pb))
            hx = pa * t1x + pb * t2x + lift * vx
            hy = pa * t1y + pb * t2y + lift * vy
            hz = pb * t2z + lift * vz
            mx, my, mz = a * hx, a * hy, np.maximum(0.0, hz)
            n = np.sqrt(mx * mx + my * my + mz * mz)
            mx, my, mz = mx / n, my / n, mz / n
            ok = valid & (mz > 0.0) & (px * mx + py * my + pz * mz > 0.0) & np.isfinite(mx + my)
            c = ix * mx + iy * my + ci * mz
            other = np.where(ci > 0.0, eta, 1.0 / eta)
            reflectance, _, cos_t = _fresnel(c, other)
            reflected = u[:, 0] < reflectance
            e = 1.0 / other
            k = (e * np.abs(c) - cos_t) * np.where(c < 0.0, -1.0, 1.0)
            wo = np.where(reflected[:, None],
                          np.stack([2.0 * c * mx - ix, 2.0 * c * my - iy, 2.0 * c * mz - ci], 1),
                          np.stack([-e * ix + k * mx, -e * iy + k * my, -e * ci + k * mz], 1))
            ok &= (wo[:, 2] != 0.0) & ((wo[:, 2] * ci > 0.0) == reflected) \
                & np.isfinite(wo).all(axis=1)
            wo = np.where(ok[:, None], wo, [0.0, 0.0, 1.0])
            value, pdf = self.evaluate(wi, wo)
            ok &= pdf > 0.0
            return (np.where(ok[:, None], wo, [0.0, 0.0, 1.0]), np.where(ok, pdf, 0.0),
                    np.where(ok, value / pdf, 0.0))


if __name__ == "__main__":
    # The same model as a child of the external protocol, to time the in-process audit against
    # it: mfh audit-external --profile ci --cmd "python3 python/tests/numpy_dielectric.py"
    import os
    import sys

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                    "examples", "external"))
    import mfh_protocol

    model = Dielectric()
    mfh_protocol.serve(
        "numpy_dielectric.py", {"ndf": {"family": "ggx", "alpha": model.alpha}, "eta": model.eta},
        {"bsdf_eval": model.eval, "bsdf_pdf": model.pdf, "bsdf_sample": model.sample},
        numpy=True, extra={"eta": model.eta, "transport": "radiance"})
