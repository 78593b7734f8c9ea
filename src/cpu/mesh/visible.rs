//! The visible parts of a mesh light's triangles (DESIGN.md §7 M3). Written next.
