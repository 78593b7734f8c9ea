#!/usr/bin/env python3
"""Writes small .npy files made by NumPy itself into tests/data/npy/, so that luxeval's reader is
tested against the real format rather than its own writer. Needs numpy."""
import os

import numpy as np

out = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "npy")
os.makedirs(out, exist_ok=True)
dirs = np.array([[0.0, -1.0, 0.0], [0.3, -0.9, 0.1], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
np.save(os.path.join(out, "dirs_f32.npy"), dirs.astype("<f4"))
np.save(os.path.join(out, "dirs_f64.npy"), dirs)  # NumPy's default dtype
np.save(os.path.join(out, "dirs_f32_fortran.npy"), np.asfortranarray(dirs.astype("<f4")))
np.save(os.path.join(out, "dirs_f32_bigendian.npy"), dirs.astype(">f4"))
np.save(os.path.join(out, "dirs_int.npy"), dirs.astype("<i4"))
np.save(os.path.join(out, "dirs_shape_4x2.npy"), dirs[:, :2].astype("<f4"))
np.save(os.path.join(out, "points_f32.npy"), np.zeros((4, 3), dtype="<f4"))
print("wrote", sorted(os.listdir(out)))
