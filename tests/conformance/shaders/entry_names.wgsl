// Entry points whose names end in a digit, as generated kernels name them
// (`execute_unary_kernel_f32`): every backend must find each by the name
// the module gives it, whatever naga's writer renames for the browser.

@group(0) @binding(0) var<storage, read_write> words: array<u32>;

@compute @workgroup_size(1)
fn fill_u32() {
    words[0] = 32u;
    words[1] = arrayLength(&words);
}

@compute @workgroup_size(1)
fn fill_f16() {
    words[2] = 16u;
}
