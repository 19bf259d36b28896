// The shaded rectangle of a compute screen pass that stands in for a scissored fragment
// pass (`PassBuilder::kernel_in`): [SCISSOR_X0, SCISSOR_X1) × [SCISSOR_Y0, SCISSOR_Y1) in
// output texels. Outside it the pass stores zero, as the fragment form's clear leaves there.
override SCISSOR_X0: u32 = 0u;
override SCISSOR_Y0: u32 = 0u;
override SCISSOR_X1: u32 = 0xffffffffu;
override SCISSOR_Y1: u32 = 0xffffffffu;

fn in_scissor(p: vec2u) -> bool {
    return all(p >= vec2u(SCISSOR_X0, SCISSOR_Y0)) && all(p < vec2u(SCISSOR_X1, SCISSOR_Y1));
}
