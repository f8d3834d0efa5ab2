// ggx_float.cpp: a float32 GGX (Trowbridge–Reitz) microfacet distribution written the way a
// renderer writes it (the structure of pbrt-v4's TrowbridgeReitzDistribution: D, Lambda, G1,
// the visible-normal density D_w(wm) and its sampler Sample_wm, plus Walter's sampler of all
// normals), every operation in `float`; mfh's doubles are rounded to float on the way in and
// the float answers widened on the way out. It speaks mfh's external protocol through
// mfh_protocol.hpp beside this file and declares "precision":"f32" in its describe answer.
//
// Build and audit (g++ or clang++, C++17; no -ffast-math: the point is IEEE float arithmetic):
//
//     g++ -std=c++17 -O2 -o ggx_float examples/external/cpp/ggx_float.cpp
//     mfh audit-external --cmd ./ggx_float --profile ci --against '{"family":"ggx","alpha":0.3}'
//
// Options: --alpha A, or --alpha-x AX --alpha-y AY (default 0.3; in [1e-4, 10]); --protocol 1|2
// (default 2); --defect vndf_pdf_without_g1, which plants the classic defect: the visible-normal
// density without G1(wi), D·max(0, wi·wm)/cos θi, whose integral over the hemisphere is
// 1 + Λ(wi) instead of 1 (1.0067 at θi = 0.5, 1.24 at θi = 1.3 for α = 0.3): the check that
// names it is mfh's sampling.pdf_visible_normalization; --defect frame_switch, pbrt-v4's frame
// of the visible-normal sampler: T1 = x̂ wherever w_h,z ≥ 0.99999 (the stretched incidence within
// 1e-5 of the normal, α tan θ < 4.5e-3), an axis not orthogonal to w_h there, so the sampled
// normals' density is off the stated one by up to ≈ 1 % (θ < 0.015 rad at α = 0.3): the check
// that names it is mfh's sampling.visible_jacobian, with the region of θ it holds in.
//
// The formulas (derived here, not copied from any renderer), for a unit vector w = (x, y, z):
//
//   D(m)   = 1 / (π αx αy (z² + (x/αx)² + (y/αy)²)²)            for z > 0, else 0
//            Walter et al. 2007 eq 33 with cos⁴θ (1 + tan²θ (cos²φ/αx² + sin²φ/αy²))² multiplied
//            out: no tan θ, no division by cos θ, so no overflow or 0·∞ near the horizon.
//   Λ(w)   = 1 / (2a (a + √(a² + 1))),  a = z / √((αx x)² + (αy y)²)   for z ≥ 0
//            Heitz 2014 ("Understanding the masking-shadowing function"), GGX: (√(1 + 1/a²) − 1)/2,
//            rewritten without the cancellation that makes the printed form 0 in float for
//            α tan θ < 2.4e-4 (pbrt-v4 writes the printed form); a = ∞ at normal incidence
//            gives 0, a = 0 at grazing gives +∞. Below the horizon Λ(w) = −1 − Λ(−w) (mfh's
//            convention; pbrt's Lambda is even in z).
//   G1(w)  = 1 / (1 + Λ(w));  the protocol's g1(w, m) is G1(w) where z > 0 and w·m > 0, else 0.
//   D_w(m) = G1(w) max(0, w·m) D(m) / cos θ_w          (Heitz 2018; pbrt-v4 uses |w·m|)
//   Visible-normal sampling (Heitz 2018, "Sampling the GGX distribution of visible normals",
//   JCGT 7(4)): stretch w to α = 1, w_h = normalize(αx x, αy y, z); an orthonormal frame
//   T1 = normalize(ẑ × w_h) (x̂ only at exactly normal incidence, as in Heitz's listing; pbrt-v4
//   takes x̂ for w_h,z ≥ 0.99999, which turns the warp's axis within 4.5e-3 rad of the normal),
//   T2 = w_h × T1; a uniform point of the
//   unit disk (r = √u1, φ = 2π u2); its T2 coordinate warped to the projected hemisphere's
//   half-disk, t2 ← (1 − s)√(1 − t1²) + s t2 with s = (1 + w_h,z)/2; lifted onto the
//   hemisphere (t3 = √(1 − t1² − t2²)); unstretched: m = normalize(αx n_x, αy n_y, max(1e-6, n_z)).
//   Normal sampling (Walter 2007 eq 35–36 in slope space): φ = 2π u1,
//   ρ = √(u2 / (1 − u2)), slope (αx ρ cos φ, αy ρ sin φ), m = normalize(slope_x, slope_y, 1);
//   its density is D(m) cos θm. These are mfh's reference conventions for u, so mfh's
//   reference answers the same m for the same u (to float precision).
//
// Uniforms are rounded to float and kept below 1 (pbrt-v4's OneMinusEpsilon, 1 − 2⁻²⁴): a
// double u within 2⁻²⁵ of 1 would otherwise round to 1.0f and ρ to infinity.

#include "mfh_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <iostream>
#include <string>

namespace {

constexpr float kPi = 3.14159265358979323846f;
/// The largest float below 1.
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

struct Vector3f {
  float x, y, z;
};
inline Vector3f operator+(Vector3f a, Vector3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vector3f operator*(float s, Vector3f v) { return {s * v.x, s * v.y, s * v.z}; }
inline Vector3f operator-(Vector3f v) { return {-v.x, -v.y, -v.z}; }
inline float Dot(Vector3f a, Vector3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vector3f Cross(Vector3f a, Vector3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vector3f Normalize(Vector3f v) { return (1.0f / std::sqrt(Dot(v, v))) * v; }
inline float Sqr(float x) { return x * x; }
inline float SafeSqrt(float x) { return std::sqrt(std::max(0.0f, x)); }
inline float Lerp(float t, float a, float b) { return (1 - t) * a + t * b; }

struct Point2f {
  float x, y;
};

/// A uniform point of the unit disk by polar coordinates: r = √u.x, φ = 2π u.y.
inline Point2f SampleUniformDiskPolar(Point2f u) {
  float r = std::sqrt(u.x);
  float theta = 2 * kPi * u.y;
  return {r * std::cos(theta), r * std::sin(theta)};
}

inline Vector3f ToFloat(const mfh::Vec3& v) {
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
}
inline mfh::Vec3 ToDouble(Vector3f v) { return {v.x, v.y, v.z}; }
inline Point2f ToFloat(const mfh::Pair& u) {
  return {std::min(static_cast<float>(u[0]), kOneMinusEpsilon),
          std::min(static_cast<float>(u[1]), kOneMinusEpsilon)};
}

enum class Defect { None, VndfPdfWithoutG1, FrameSwitch };

class TrowbridgeReitzDistribution {
 public:
  TrowbridgeReitzDistribution(float alpha_x, float alpha_y, Defect defect)
      : alpha_x(alpha_x), alpha_y(alpha_y), defect(defect) {}

  /// The distribution of normals D(m) (per steradian, ∫ D(m) cos θm dm = 1).
  float D(Vector3f wm) const {
    if (!(wm.z > 0)) return 0;
    float t = Sqr(wm.z) + Sqr(wm.x / alpha_x) + Sqr(wm.y / alpha_y);
    return 1 / (kPi * alpha_x * alpha_y * Sqr(t));
  }

  /// Smith's Λ(w), both hemispheres.
  float Lambda(Vector3f w) const {
    if (w.z < 0) return -1 - Lambda(-w);
    float t = std::hypot(alpha_x * w.x, alpha_y * w.y);
    if (t == 0) return 0;  // normal incidence
    float a = w.z / t;     // 0 at grazing: Λ = +∞
    return 1 / (2 * a * (a + std::sqrt(Sqr(a) + 1)));
  }

  /// The masking function G1(w) = 1 / (1 + Λ(w)).
  float G1(Vector3f w) const { return 1 / (1 + Lambda(w)); }

  /// The distribution of normals visible from w, D_w(wm) = G1(w) max(0, w·wm) D(wm) / cos θw:
  /// the density of Sample_wm(w, ·).
  float D(Vector3f w, Vector3f wm) const {
    if (!(w.z > 0)) return 0;
    float cosine = std::max(0.0f, Dot(w, wm));
    if (defect == Defect::VndfPdfWithoutG1) return cosine * D(wm) / w.z;  // the planted defect
    return G1(w) / w.z * D(wm) * cosine;
  }

  float PDF(Vector3f w, Vector3f wm) const { return D(w, wm); }

  /// A normal visible from w (w.z > 0), distributed as D(w, ·) (Heitz 2018).
  Vector3f Sample_wm(Vector3f w, Point2f u) const {
    Vector3f wh = Normalize({alpha_x * w.x, alpha_y * w.y, w.z});
    if (wh.z < 0) wh = -wh;
    bool tilted = defect == Defect::FrameSwitch ? wh.z < 0.99999f : Sqr(wh.x) + Sqr(wh.y) > 0;
    Vector3f T1 = tilted ? Normalize(Cross({0, 0, 1}, wh)) : Vector3f{1, 0, 0};
    Vector3f T2 = Cross(wh, T1);
    Point2f p = SampleUniformDiskPolar(u);
    float h = std::sqrt(1 - Sqr(p.x));
    p.y = Lerp((1 + wh.z) / 2, h, p.y);
    float pz = SafeSqrt(1 - Sqr(p.x) - Sqr(p.y));
    Vector3f nh = p.x * T1 + p.y * T2 + pz * wh;
    return Normalize({alpha_x * nh.x, alpha_y * nh.y, std::max(1e-6f, nh.z)});
  }

  /// A normal distributed as D(m) cos θm (Walter 2007, in slope space).
  Vector3f SampleAllNormals(Point2f u) const {
    float phi = 2 * kPi * u.x;
    float rho = std::sqrt(u.y / (1 - u.y));
    return Normalize({alpha_x * rho * std::cos(phi), alpha_y * rho * std::sin(phi), 1});
  }

  /// The density of SampleAllNormals: D(m) cos θm.
  float PdfAllNormals(Vector3f wm) const { return wm.z > 0 ? D(wm) * wm.z : 0; }

 private:
  float alpha_x, alpha_y;
  Defect defect;
};

}  // namespace

int main(int argc, char** argv) {
  double ax = 0.3, ay = 0.3;
  int protocol = 2;
  Defect defect = Defect::None;
  std::string defect_name = "none";
  try {
    mfh::Options opts(argc, argv);
    opts.only({"--alpha", "--alpha-x", "--alpha-y", "--protocol", "--defect"});
    double alpha = opts.number("--alpha", 0.3, 1e-4, 10);
    ax = opts.number("--alpha-x", alpha, 1e-4, 10);
    ay = opts.number("--alpha-y", opts.has("--alpha-x") ? ax : alpha, 1e-4, 10);
    double version = opts.number("--protocol", 2, 1, 2);
    if (version != 1 && version != 2) throw std::invalid_argument("--protocol must be 1 or 2");
    protocol = static_cast<int>(version);
    defect_name = opts.text("--defect", "none");
    if (defect_name == "vndf_pdf_without_g1") {
      defect = Defect::VndfPdfWithoutG1;
    } else if (defect_name == "frame_switch") {
      defect = Defect::FrameSwitch;
    } else if (defect_name != "none") {
      throw std::invalid_argument("--defect is \"" + defect_name +
                                  "\"; known: none, vndf_pdf_without_g1, frame_switch");
    }
  } catch (const std::exception& e) {
    std::cerr << "ggx_float: " << e.what() << "\n";
    return 2;
  }

  const TrowbridgeReitzDistribution ggx(static_cast<float>(ax), static_cast<float>(ay), defect);

  mfh::Model model;
  model.name = defect == Defect::None ? "ggx_float.cpp" : "ggx_float.cpp --defect " + defect_name;
  model.parameters = mfh::Json::object({{"family", "ggx"}, {"alpha_x", ax}, {"alpha_y", ay}});
  if (defect != Defect::None) model.parameters.set("defect", defect_name);
  model.describe_extra = {{"precision", "f32"}};
  model.d = [&](const mfh::Vec3& m) { return double(ggx.D(ToFloat(m))); };
  model.lambda = [&](const mfh::Vec3& w) { return double(ggx.Lambda(ToFloat(w))); };
  model.g1 = [&](const mfh::Vec3& w, const mfh::Vec3& m) {
    Vector3f wf = ToFloat(w), mf = ToFloat(m);
    return wf.z > 0 && Dot(wf, mf) > 0 ? double(ggx.G1(wf)) : 0.0;
  };
  model.sample_wm = [&](const mfh::Pair& u) { return ToDouble(ggx.SampleAllNormals(ToFloat(u))); };
  model.pdf_wm = [&](const mfh::Vec3& m) { return double(ggx.PdfAllNormals(ToFloat(m))); };
  model.sample_wm_visible = [&](const mfh::Vec3& wi, const mfh::Pair& u) {
    return ToDouble(ggx.Sample_wm(ToFloat(wi), ToFloat(u)));
  };
  model.pdf_wm_visible = [&](const mfh::Vec3& wi, const mfh::Vec3& m) {
    return double(ggx.PDF(ToFloat(wi), ToFloat(m)));
  };
  return mfh::serve(model, protocol);
}
