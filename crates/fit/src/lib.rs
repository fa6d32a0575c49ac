//! paperbsdf-fit (work in progress)
