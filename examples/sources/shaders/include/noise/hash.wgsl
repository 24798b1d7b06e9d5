// A lattice value in [0, 1) from a cell and a seed: 24 high bits of nested PCG.
fn lattice(cell: vec2<i32>, seed: u32) -> f32 {
    let h = pcg(bitcast<u32>(cell.x) ^ pcg(bitcast<u32>(cell.y) ^ pcg(seed)));
    return f32(h >> 8u) / 16777216.0;
}
