//! Source assembly (SPEC 16): the WGSL text of one pass as a project's host
//! builds it before the compiler sees it — textual `#include`, files joined
//! before and after the shader, literal text replacements — with every
//! assembled line traced to the file and line it came from, so errors name
//! the file the user wrote.
//!
//! `.wesl` shaders compile through the `wesl` crate ([`compile_wesl`]).
//!
//! Not for: `#import` and shader defs (naga_oil's, in `vista-gpu`), or
//! reading files: the caller hands in a reader, so this crate does no
//! I/O and knows no project layout.
#![deny(missing_docs)]

mod assemble;
mod spec;
mod wesl;

pub use assemble::{Assembled, Part, assemble};
pub use spec::{Replacement, SourceSpec};
pub use wesl::compile_wesl;
