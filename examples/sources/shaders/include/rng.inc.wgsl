// PCG hash (Jarzynski and Olano 2020): one LCG step, then a permutation
// chosen by the state's top bits.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
