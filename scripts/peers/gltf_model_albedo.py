#!/usr/bin/env python3
"""Directional albedo of a smooth dielectric over a diffuse base (a glTF
material with metallic 0, roughness 0, ior 1.5) as the two models define it,
at a few view angles: what a white sky of radiance 1 makes of it, ignoring
interreflection. numpy only.

    gltf_model_albedo.py [--base 0.6038] [--ior 1.5]

glTF 2.0 Appendix B (lumen):  A(mu) = F_s(mu) + base * W(mu),
  F_s = Schlick's Fresnel (f0 = ((ior - 1)/(ior + 1))^2, f90 = 1) of the mirror
  reflection, and W(mu) = integral over the hemisphere of
  (1 - F_s(V.H)) cos(theta_i) / pi d omega_i: the diffuse weighted per light
  direction by one minus the Fresnel of its own half vector.
Cycles Principled BSDF v2:  A(mu) = F(mu) + base * (1 - F(mu)),
  F = the exact dielectric Fresnel, the diffuse scaled by one minus the
  specular layer's albedo at the view (for a smooth layer, F itself):
  energy conserving.
W(mu) stays near 0.95 at every angle while 1 - F(mu) falls to 0 at grazing
incidence: the glTF material reflects more than Cycles' towards silhouettes
(more than 1 at mu < 0.17 for base 0.6).
"""

import argparse

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=float, default=0.6038)
    ap.add_argument("--ior", type=float, default=1.5)
    args = ap.parse_args()
    n = args.ior
    f0 = ((n - 1) / (n + 1)) ** 2

    def schlick(c):
        return f0 + (1 - f0) * (1 - c) ** 5

    def exact(c):
        s2 = 1 - c * c
        ct = np.sqrt(1 - s2 / n ** 2)
        rs = (c - n * ct) / (c + n * ct)
        rp = (n * c - ct) / (n * c + ct)
        return 0.5 * (rs ** 2 + rp ** 2)

    N = 400
    th = (np.arange(N) + 0.5) / N * np.pi / 2
    ph = (np.arange(2 * N) + 0.5) / (2 * N) * 2 * np.pi
    T, P = np.meshgrid(th, ph, indexing="ij")
    wi = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    dw = np.sin(T) * (np.pi / 2 / N) * (2 * np.pi / (2 * N))
    print(f"base {args.base}, ior {n} (f0 {f0:.4f})")
    print("| mu = cos(view) | glTF F_s | glTF W | glTF albedo | Cycles F | Cycles 1-F | Cycles albedo | glTF / Cycles - 1 |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for mu in [1.0, 0.866, 0.7, 0.5, 0.436, 0.3, 0.2, 0.1]:
        v = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
        h = wi + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        w = float(np.sum((1 - schlick(h @ v)) * wi[..., 2] / np.pi * dw))
        ag = schlick(mu) + args.base * w
        fc = exact(mu)
        ac = fc + args.base * (1 - fc)
        print(f"| {mu:.3f} | {schlick(mu):.4f} | {w:.4f} | {ag:.4f} | {fc:.4f} | {1 - fc:.4f} | {ac:.4f} | {100 * (ag / ac - 1):+.1f}% |")
    return 0


if __name__ == "__main__":
    main()
