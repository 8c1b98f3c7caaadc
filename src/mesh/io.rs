//! Mesh and field output (VTU).
