// Unit tests of vista::phase (`vista test`). Expected values from the
// formulas of SPEC 3.5 and 3.6, computed in f64 (Python's math module).
#import vista::phase::{rayleigh_phase, hg_phase, dual_hg_phase}
#import wgsl_test::{expectNear}

@test
fn rayleigh_at_right_angles_and_forward() {
    // 3 / (16 pi) (1 + mu^2) at mu = 0 and 1.
    expectNear(rayleigh_phase(0.0), 0.05968310365946075);
    expectNear(rayleigh_phase(1.0), 0.1193662073189215);
}

@test
fn hg_isotropic_is_one_over_four_pi() {
    expectNear(hg_phase(0.3, 0.0), 0.07957747154594767);
    expectNear(hg_phase(-0.9, 0.0), 0.07957747154594767);
}

@test
fn hg_forward_and_backward_peaks() {
    // (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5) at g = 0.5, mu = +1 and -1.
    expectNear(hg_phase(1.0, 0.5), 0.477464829275686);
    expectNear(hg_phase(-1.0, 0.5), 0.01768388256576615);
}

@test
fn dual_lobe_blends_its_lobes() {
    // blend 0 is the first lobe, 1 the second.
    expectNear(dual_hg_phase(1.0, 0.5, 0.0, 0.0), 0.477464829275686);
    expectNear(dual_hg_phase(1.0, 0.5, 0.0, 1.0), 0.07957747154594767);
}
