"""The glTF 2.0 metallic-roughness BRDF as a Mitsuba 3 BSDF ("gltf"), so that Mitsuba's path
tracer renders the BRDF splitsum is measured against, not a neighbour of it.

Khronos glTF 2.0 specification, Appendix B (B.3.4 fresnel_mix and conductor_fresnel, B.3.5):

    f = (1 - metallic) (1 - F_d) base / pi  +  F D V,
    F_d = 0.04 + 0.96 (1 - v.h)^5,  F = F0 + (1 - F0)(1 - v.h)^5,  F0 = mix(0.04, base, metallic),
    D = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2),  a = roughness^2,
    V = 0.5 / ((n.l) sqrt((n.v)^2 (1 - a^2) + a^2) + (n.v) sqrt((n.l)^2 (1 - a^2) + a^2)),

V being the height-correlated Smith term G2 / (4 (n.l)(n.v)) of the specification's
B.3.2. Mitsuba's own `roughconductor` uses the separable G1(v) G1(l) instead, and no Mitsuba
BSDF is `fresnel_mix` of Lambert and GGX. This is the same formula as
`splitsum_reference::gltf_brdf_cos` with `Smith::Correlated`, written again here for
Mitsuba's JIT (a second, independent implementation: Mitsuba samples it, the reference sums it).

Sampling: GGX's visible normals (Mitsuba's `MicrofacetDistribution`) for the specular layer
and the cosine for the diffuse one, chosen with probability `(1 - metallic) / 2`; the pdf is
the mixture's, so the estimator is unbiased whichever is drawn.

Properties: `base_r`, `base_g`, `base_b`, `metallic`, `roughness`. Needs a JIT variant
(`llvm_ad_rgb`): Python BSDFs run once per wavefront there, not once per path.
"""
import drjit as dr
import mitsuba as mi


class GltfBsdf(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        self.base = mi.Color3f(props["base_r"], props["base_g"], props["base_b"])
        self.metallic = float(props["metallic"])
        roughness = float(props["roughness"])
        self.alpha = max(roughness * roughness, 1e-4)
        self.p_diffuse = 0.5 * (1.0 - self.metallic)
        glossy = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
        diffuse = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide
        self.m_components = [glossy, diffuse]
        self.m_flags = glossy | diffuse

    def _distribution(self):
        return mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)

    def _eval(self, wi, wo):
        """f(wi, wo) cos(wo) per channel, 0 where either direction is under the surface."""
        nv = mi.Frame3f.cos_theta(wi)
        nl = mi.Frame3f.cos_theta(wo)
        h = dr.normalize(wi + wo)
        nh = mi.Frame3f.cos_theta(h)
        vh = dr.clip(dr.dot(wi, h), 0.0, 1.0)
        a2 = self.alpha * self.alpha
        d = a2 / (dr.pi * dr.square(nh * nh * (a2 - 1.0) + 1.0))
        v = 0.5 / (nl * dr.sqrt(nv * nv * (1.0 - a2) + a2) + nv * dr.sqrt(nl * nl * (1.0 - a2) + a2))
        fc = dr.power(1.0 - vh, 5.0)
        f_dielectric = 0.04 + 0.96 * fc
        f0 = 0.04 + (self.base - 0.04) * self.metallic
        f = f0 + (1.0 - f0) * fc
        value = ((1.0 - self.metallic) * (1.0 - f_dielectric) * self.base / dr.pi + f * (d * v)) * nl
        return dr.select((nv > 0.0) & (nl > 0.0), value, 0.0)

    def _pdf(self, wi, wo):
        nl = mi.Frame3f.cos_theta(wo)
        h = dr.normalize(wi + wo)
        specular = self._distribution().pdf(wi, h) / (4.0 * dr.abs(dr.dot(wo, h)))
        diffuse = mi.warp.square_to_cosine_hemisphere_pdf(wo)
        pdf = self.p_diffuse * diffuse + (1.0 - self.p_diffuse) * specular
        return dr.select((mi.Frame3f.cos_theta(wi) > 0.0) & (nl > 0.0), pdf, 0.0)

    def sample(self, ctx, si, sample1, sample2, active):
        m, _ = self._distribution().sample(si.wi, sample2)
        pick_diffuse = sample1 < self.p_diffuse
        wo = dr.select(pick_diffuse, mi.warp.square_to_cosine_hemisphere(sample2), mi.reflect(si.wi, m))
        bs = mi.BSDFSample3f()
        bs.wo = wo
        bs.pdf = self._pdf(si.wi, wo)
        bs.eta = 1.0
        bs.sampled_component = dr.select(pick_diffuse, mi.UInt32(1), mi.UInt32(0))
        bs.sampled_type = dr.select(pick_diffuse, mi.UInt32(+mi.BSDFFlags.DiffuseReflection), mi.UInt32(+mi.BSDFFlags.GlossyReflection))
        ok = active & (bs.pdf > 0.0)
        value = dr.select(ok, self._eval(si.wi, wo) / dr.select(ok, bs.pdf, 1.0), 0.0)
        return (bs, value)

    def eval(self, ctx, si, wo, active):
        return dr.select(active, self._eval(si.wi, wo), 0.0)

    def pdf(self, ctx, si, wo, active):
        return dr.select(active, self._pdf(si.wi, wo), 0.0)

    def eval_pdf(self, ctx, si, wo, active):
        return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

    def to_string(self):
        return f"GltfBsdf[metallic={self.metallic}, alpha={self.alpha}]"


def register():
    mi.register_bsdf("gltf", lambda props: GltfBsdf(props))
