//! Long-ish runs against measured behaviour (relaxation of the paper's scene).
