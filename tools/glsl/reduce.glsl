// reduce.glsl - the work-group sum shared by the gather and apply kernels (one copy of the
// reduction instead of one per kernel). Included after the kernel's layout(local_size...)
// line: glslangValidator resolves the #include (GL_GOOGLE_include_directive), and `make glsl`
// pastes this text in its place in the header's copy, so the embedded kernels need no includer.

shared vec3 rad_partial[gl_WorkGroupSize.x];

// The sum of v over the work group, returned to every invocation. Every invocation of the
// group must call it (it holds barriers), once per kernel run: a second call would overwrite
// rad_partial while slower invocations may still read the first result. The pairs are added
// in a fixed tree order, halving the width each step, so any group size works and no subgroup
// operation is assumed.
vec3 rad_group_sum(vec3 v)
{
    uint lid = gl_LocalInvocationID.x;
    rad_partial[lid] = v;
    barrier();
    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {
        uint h = (width + 1u) / 2u;
        if (lid < width - h) rad_partial[lid] += rad_partial[lid + h];
        barrier();
        width = h;
    }
    return rad_partial[0];
}
