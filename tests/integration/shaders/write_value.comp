#version 450
// The app's own compute work in capture_reduce_test.cpp: writes its push constant into every element of its
// storage buffer (set 0, binding 0), one invocation per element.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint values[]; };
layout(push_constant) uniform Value { uint value; };
void main() { values[gl_GlobalInvocationID.x] = value; }
