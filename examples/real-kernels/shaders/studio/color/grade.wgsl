// A project's own colour module under its own import path. GRADE_STEPS, a
// shader def with a value from the kernel's manifest, sets how many bands
// posterize() keeps.
#define_import_path studio::color::grade

#ifdef GRADE_STEPS
const STEPS: f32 = f32(#GRADE_STEPS);
#else
const STEPS: f32 = 8.0;
#endif

// x in [0, 1] quantised to STEPS bands, each shown at its centre.
fn posterize(x: f32) -> f32 {
    return (floor(clamp(x, 0.0, 0.999999) * STEPS) + 0.5) / STEPS;
}

// Smooth contrast around 0.5: 3x^2 - 2x^3 blended by `amount`.
fn contrast(x: f32, amount: f32) -> f32 {
    return mix(x, x * x * (3.0 - 2.0 * x), amount);
}
