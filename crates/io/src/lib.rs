//! paperbsdf-io (work in progress)
