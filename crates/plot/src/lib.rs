//! paperbsdf-plot (work in progress)
