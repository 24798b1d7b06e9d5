// A WGSL unit test beside the golden cases: `vista::harness::main()` runs
// it as the libtest test wgsl::glow::core_is_one_over_e_at_the_radius.
// The glow's core is exp(-(r / radius)^2): 1/e = 0.36787944 at r = radius.
#import wgsl_test::{expectNear}

@test
fn core_is_one_over_e_at_the_radius() {
    let radius = 0.35;
    let r = 0.35;
    expectNear(exp(-(r / radius) * (r / radius)), 0.36787944);
}
