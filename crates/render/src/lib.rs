//! paperbsdf-render (work in progress)
