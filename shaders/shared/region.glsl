// Dispatches over a rectangle of an image or pyramid level (ComputeStages::runOverRegion):
// invocation (0, 0) works on texel `dispatchOrigin`, and texels from `dispatchEnd` on are past
// the rectangle.

layout(location = SUBSCAN_UNIFORM_ORIGIN) uniform ivec2 dispatchOrigin;
layout(location = SUBSCAN_UNIFORM_END) uniform ivec2 dispatchEnd;

ivec2 dispatchTexel() { return ivec2(gl_GlobalInvocationID.xy) + dispatchOrigin; }

/// Whether `texel` lies in the rectangle. Work groups round it up, and a texel past it must not
/// be written: its inputs were not computed for this frame, and later passes may read it.
bool insideRegion(ivec2 texel) { return all(lessThan(texel, dispatchEnd)); }
