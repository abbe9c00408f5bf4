// insolation.cl: the steps of one sun-azimuth bucket added to every pixel's sunshine hours and
// direct irradiation (computeInsolation in src/ops/insolation.cpp, which sweeps the bucket's
// horizon). Global size: pixels rounded up to the group.
#pragma OPENCL FP_CONTRACT OFF

// The fraction of a disc of angular radius `radius` whose centre stands `above` above a straight
// horizon (discAboveHorizon in the library).
inline float disc_above(float above, float radius) {
  const float t = clamp(above / radius, -1.0f, 1.0f);
  return 1.0f - (acos(t) - t * sqrt(1.0f - t * t)) / M_PI_F;
}

// horizon: the bucket's elevation plane (NaN at nodata); normals: unit normals (x, y, z, 0);
// steps[i]: the sun's unit vector (x, y, z) and elevation (w, radians), hours[i] its duration.
__kernel void insolation_add(__global const float* horizon, __global const float4* normals, uint pixels,
                             __global const float4* steps, __global const float* hours, int n_steps, float radius,
                             __global float* sun_hours, __global float* direct) {
  const uint p = get_global_id(0);
  if (p >= pixels) return;
  const float h = horizon[p];
  if (isnan(h)) {
    sun_hours[p] = NAN;
    direct[p] = NAN;
    return;
  }
  const float limit = fmax(h, 0.0f);  // level ground beyond the field
  const float4 n = normals[p];
  float up = 0.0f, light = 0.0f;
  for (int i = 0; i < n_steps; ++i) {
    const float4 s = steps[i];
    const float cosine = n.x * s.x + n.y * s.y + n.z * s.z;
    up += s.w > limit ? hours[i] : 0.0f;
    light += hours[i] * disc_above(s.w - limit, radius) * fmax(cosine, 0.0f);
  }
  sun_hours[p] += up;
  direct[p] += light;
}
