//! The same CPU references (each kernel's `cpu.rs`, `src/cpu/`) compiled with f32 arithmetic: the
//! CPU doing the GPU's work at the GPU's precision, the baseline of the
//! throughput benches, and a measure of what the f64 oracles buy (see
//! `tests/precision.rs`, which checks it against the f64 build; the unit
//! test below checks that it computes in f32). Not an
//! oracle: no GPU test compares against it, except the heightfield relax
//! march port (`HitSearch::RelaxMarch`), checked to do the GPU's work.

// Both builds load the same files, on purpose.
#![allow(clippy::duplicate_mod)]

cpu_references!(f32, glam::Vec3);

#[cfg(test)]
mod tests {
    #[test]
    fn computes_in_f32_and_holds_perlins_reference_value() {
        assert_eq!(size_of::<super::Real>(), 4);
        assert_eq!(size_of::<crate::cpu64::Real>(), 8);
        let p = crate::noise::permutation(0);
        #[allow(clippy::approx_constant)] // SPEC 3.1's input, not pi
        let v = super::noise::perlin(&p, 3.14, 42.0, 7.0);
        assert!((v - 0.136_919_96).abs() < 1e-6, "f32 perlin(3.14, 42, 7) = {v}");
    }
}
