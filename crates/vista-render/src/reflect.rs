//! What the composed module says of a dispatch, read with naga.

/// The entry point's workgroup size; where it names `override`s, their
/// values are substituted first.
pub(crate) fn workgroup_size(
    module: &naga::Module,
    entry: &str,
    constants: &[(String, f64)],
) -> Result<[u32; 3], String> {
    let find = |m: &naga::Module| {
        m.entry_points
            .iter()
            .find(|e| e.name == entry && e.stage == naga::ShaderStage::Compute)
            .map(|e| (e.workgroup_size, e.workgroup_size_overrides.is_some()))
            .expect("Kernel::layout refuses an unknown entry point")
    };
    match find(module) {
        (size, false) => Ok(size),
        (_, true) => {
            let (resolved, _) =
                vista_gpu::resolve_overrides(entry, module, entry, constants).map_err(|e| e.to_string())?;
            Ok(find(&resolved).0)
        }
    }
}
