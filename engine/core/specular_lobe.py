"""What the specular layer of the scene format's BRDF (glsl/lib/brdf.glsl) reflects in all,
integrated over the light's directions: the table the shaders read it from.

The layer is f_s(l, v) = F(v.h) D(h) G1(n.l) G1(n.v) / (4 n.l n.v) with the normalized
Blinn-Phong D of exponent s = 2 / r^4 - 2, Smith's G1 of the Beckmann lobe of alpha = r^2 and
Schlick's F = F0 + (1 - F0) (1 - v.h)^5. Its directional albedo, lit from every direction by
radiance 1 and seen from v at cos_view to the normal,

    A(cos_view, r, F0) = int f_s(l, v) n.l dl = F0 scale + bias,

is linear in F0 (F is): scale = int f_s (1 - (1 - v.h)^5) / F n.l dl, bias = int f_s (1 - v.h)^5 / F n.l dl
(the split of Karis's "split sum"). Smith's masking makes A < F: a rough lobe loses light
between its microfacets (r = 1, F0 = 0.04: A = 0.027 against the hemispherical mean of F, 0.086),
so a layer weighted by F alone would reflect more than the model. The cone tracer weighs the
specular cone by A at the camera's direction, and voxels pass on the layered albedo with A's
hemispherical mean (2 int A(mu) mu dmu). By reciprocity A is also what the layer reflects of
light arriving from v.
"""
import numpy as np

from .constants import MIN_ROUGHNESS

# Nodes of the table per axis: cos_view and roughness at i / (SIZE - 1).
SPECULAR_ALBEDO_SIZE = 16
# Stratified half-vector samples per axis of one directional albedo.
_SAMPLES = 48


def blinn_phong_exponent(roughness):
    """s = 2 / r^4 - 2 of roughness r (clamped to MIN_ROUGHNESS), as lib/brdf.glsl."""
    return max(2.0 / max(roughness, MIN_ROUGHNESS) ** 4 - 2.0, 0.0)


def smith_g1(cos_theta, alpha):
    """Smith's G1 of the Beckmann lobe (Walter et al. 2007's rational fit), as lib/brdf.glsl."""
    c = np.clip(cos_theta, 1e-4, 1.0)
    a = c / (alpha * np.sqrt(1.0 - c * c) + 1e-7)
    return np.where(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a))


def directional_albedo(cos_view, roughness):
    """(scale, bias) of A(cos_view, r, F0) = F0 scale + bias for an array of cos_view: shape
    (len, 2). The half vectors are drawn from D(h) n.h on a fixed stratified grid
    (deterministic)."""
    s = blinn_phong_exponent(roughness)
    alpha = max(roughness, MIN_ROUGHNESS) ** 2
    mu = np.maximum(np.asarray(cos_view, float), 1e-3)[:, None, None]
    u = (np.arange(_SAMPLES) + 0.5) / _SAMPLES
    u1, u2 = np.meshgrid(u, u)
    cos_h = u1 ** (1.0 / (s + 2.0))  # pdf of h: D(h) n.h
    sin_h = np.sqrt(np.maximum(1.0 - cos_h * cos_h, 0.0))
    v_h = np.sqrt(1.0 - mu * mu) * sin_h * np.cos(2 * np.pi * u2) + mu * cos_h  # v = (sin, 0, cos)
    cos_l = 2.0 * v_h * cos_h - mu  # l = 2 (v.h) h - v, n = z
    above = (cos_l > 0.0) & (v_h > 0.0)
    # f_s n.l / pdf(l) / F, with pdf(l) = D n.h / (4 v.h)
    weight = np.where(above, smith_g1(cos_l, alpha) * smith_g1(mu, alpha) * v_h / (mu * cos_h), 0.0)
    grazing = (1.0 - np.clip(v_h, 0.0, 1.0)) ** 5
    return np.stack([np.mean(weight * (1.0 - grazing), axis=(1, 2)), np.mean(weight * grazing, axis=(1, 2))], axis=-1)


def hemispherical_albedo(roughness):
    """(scale, bias) of A's mean over the cosine-weighted hemisphere, 2 int A(mu) mu dmu
    (Gauss-Legendre in mu)."""
    nodes, weights = np.polynomial.legendre.leggauss(24)
    mus = 0.5 * (nodes + 1.0)
    return (weights * mus) @ directional_albedo(mus, roughness)  # 2 * (1/2 sum w_i mu_i A_i)


def tables():
    """(directional, hemispherical): (SIZE, SIZE, 2) over [roughness][cos_view] and (SIZE, 2)
    over roughness, at the nodes i / (SIZE - 1)."""
    nodes = np.linspace(0.0, 1.0, SPECULAR_ALBEDO_SIZE)
    directional = np.array([directional_albedo(nodes, r) for r in nodes])
    hemispherical = np.array([hemispherical_albedo(r) for r in nodes])
    return directional, hemispherical


def glsl_tables():
    """GLSL lines of the tables (lib/brdf.glsl reads them)."""
    directional, hemispherical = tables()
    vec2 = lambda pair: f"vec2({pair[0]:.6f}, {pair[1]:.6f})"
    n = SPECULAR_ALBEDO_SIZE
    return [f"#define SPECULAR_ALBEDO_SIZE {n}",
            f"const vec2 SPECULAR_ALBEDO[{n * n}] = vec2[]({', '.join(vec2(p) for p in directional.reshape(-1, 2))});",
            f"const vec2 SPECULAR_HEMISPHERICAL_ALBEDO[{n}] = vec2[]({', '.join(vec2(p) for p in hemispherical)});"]
