#!/usr/bin/env python3
"""Writes the quick-start arrays in assets/: dirs.npy (4096 Fibonacci-sphere directions),
floor_points.npy (a 64 x 64 grid of the floor y = 0 over x, z in [-4, 4]) and floor_up.npy (+Y
normals for it). All float32 (N, 3). Needs numpy."""
import os

import numpy as np

out = os.path.join(os.path.dirname(__file__), "..", "assets")
n = 4096
i = np.arange(n) + 0.5
z = 1 - 2 * i / n
phi = np.pi * (1 + 5 ** 0.5) * i
r = np.sqrt(1 - z * z)
np.save(os.path.join(out, "dirs.npy"), np.stack([r * np.cos(phi), z, r * np.sin(phi)], axis=1).astype("<f4"))
g = (np.arange(64) + 0.5) / 64 * 8 - 4
X, Z = np.meshgrid(g, g)
pts = np.stack([X.ravel(), np.zeros(X.size), Z.ravel()], axis=1).astype("<f4")
np.save(os.path.join(out, "floor_points.npy"), pts)
np.save(os.path.join(out, "floor_up.npy"), np.tile(np.array([[0.0, 1.0, 0.0]], dtype="<f4"), (len(pts), 1)))
print("wrote assets/dirs.npy, floor_points.npy, floor_up.npy")
