#!/usr/bin/env python3
"""Writes assets/neon_ring.usda: a neon-like ring (a polygonal torus with MeshLightAPI, fronts
facing out of the tube) 1.2 units above the luxtest floor, for the README's mesh-light falloff
map. Plain text, no USD library needed; usd-core opens it (checked by the README's command).

    python3 tools/gen_neon_ring.py > assets/neon_ring.usda
"""
import math

RING, TUBE, HEIGHT = 2.0, 0.08, 1.2
AROUND, ACROSS = 64, 8

points, counts, indices = [], [], []
for i in range(AROUND):
    a = 2 * math.pi * i / AROUND
    for j in range(ACROSS):
        b = 2 * math.pi * j / ACROSS
        rho = RING + TUBE * math.cos(b)
        points.append((rho * math.cos(a), HEIGHT + TUBE * math.sin(b), rho * math.sin(a)))


def v(i, j):
    return (i % AROUND) * ACROSS + (j % ACROSS)


for i in range(AROUND):
    for j in range(ACROSS):
        # Wound so that (p1 - p0) x (p2 - p0) points out of the tube (rightHanded).
        counts.append(4)
        indices += [v(i, j), v(i, j + 1), v(i + 1, j + 1), v(i + 1, j)]


def fmt(p):
    return "(" + ", ".join(f"{c:.6f}" for c in p) + ")"


print('#usda 1.0\n(\n    upAxis = "Y"\n    metersPerUnit = 1\n)\n')
print('def Mesh "NeonRing" (\n    prepend apiSchemas = ["MeshLightAPI"]\n)\n{')
print('    uniform token subdivisionScheme = "none"')
print('    uniform token light:materialSyncMode = "independent"')
print("    float inputs:intensity = 30")
print("    color3f inputs:color = (1, 0.25, 0.7)")
print("    int[] faceVertexCounts = [" + ", ".join(map(str, counts)) + "]")
print("    int[] faceVertexIndices = [" + ", ".join(map(str, indices)) + "]")
print("    point3f[] points = [" + ", ".join(fmt(p) for p in points) + "]")
print("}")
