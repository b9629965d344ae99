// Dispatches over a rectangle of an image or pyramid level (ComputeStages::runOverRegion):
// invocation (0, 0) works on texel `dispatchOrigin`.

layout(location = SUBSCAN_UNIFORM_ORIGIN) uniform ivec2 dispatchOrigin;

ivec2 dispatchTexel() { return ivec2(gl_GlobalInvocationID.xy) + dispatchOrigin; }
