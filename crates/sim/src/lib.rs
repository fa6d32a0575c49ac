//! paperbsdf-sim (work in progress)
