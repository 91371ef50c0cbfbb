// A pixel's footprint on its shading texture (renderer/footprint.py): the texture's mean
// over it, read one of two ways, chosen when the program is compiled (FOOTPRINT_BOX for
// render.lod.texture_filter `box`), not by a branch: llvmpipe runs both sides of one.
// `texel_at`: the pixel's centre in the layer's level-0 texel coordinates (texel centres
// at integers); `across`, `down`: the footprint's sides, in level-0 texels per pixel.
uniform float texture_side;      // texels a side of level 0 (cells 2^levels + 1)
uniform float level_bias;        // trilinear: log2 of the filter's width against the footprint (footprint.LOD_BIAS)

#ifdef FOOTPRINT_BOX
const float BOX_MIN_TEXELS = 1.41421356;  // footprint.BOX_MIN_TEXELS

// The box's overlap with the four texels from `first` (each 1 wide, centred on an integer).
vec4 box_overlaps(float first, float lo, float hi)
{
    vec4 centre = first + vec4(0.0, 1.0, 2.0, 3.0);
    return max(min(vec4(hi), centre + 0.5) - max(vec4(lo), centre - 0.5), 0.0);
}

// footprint.box_footprint: the pixel's box along each texture axis, integrated over level
// k's texels as constants. Four texels a side at most, read as two linear pairs: texels
// weighted (a, b) are one bilinear read b / (a + b) past the first, times a + b.
vec4 footprint_mean(sampler2DArray shading, vec2 texel_at, float layer, vec2 across, vec2 down)
{
    vec2 width = sqrt(across * across + down * down);          // level-0 texels
    float k = clamp(floor(log2(max(width.x, width.y) / BOX_MIN_TEXELS)), 0.0, floor(log2(texture_side)));
    vec2 width_k = width * exp2(-k);
    vec2 box = k == 0.0 ? sqrt(width_k * width_k + 1.0) : sqrt(max(width_k * width_k - 2.0, 1.0));
    // level k has floor(side / 2^k) texels a side, over the same [0, 1] (footprint.mip_levels)
    float side_k = floor(texture_side * exp2(-k));
    vec2 centre = (texel_at + 0.5) * (side_k / texture_side) - 0.5;
    vec2 lo = centre - 0.5 * box, hi = centre + 0.5 * box;
    vec2 first = floor(lo + 0.5);
    vec4 wx = box_overlaps(first.x, lo.x, hi.x), wy = box_overlaps(first.y, lo.y, hi.y);
    vec2 sx = wx.xz + wx.yw, sy = wy.xz + wy.yw;                // the pairs' weights
    vec2 ux = (first.x + vec2(0.5, 2.5) + wx.yw / max(sx, 1e-9)) / side_k;
    vec2 uy = (first.y + vec2(0.5, 2.5) + wy.yw / max(sy, 1e-9)) / side_k;
    vec4 sum = sx.x * sy.x * textureLod(shading, vec3(ux.x, uy.x, layer), k)
             + sx.y * sy.x * textureLod(shading, vec3(ux.y, uy.x, layer), k)
             + sx.x * sy.y * textureLod(shading, vec3(ux.x, uy.y, layer), k)
             + sx.y * sy.y * textureLod(shading, vec3(ux.y, uy.y, layer), k);
    return sum / ((sx.x + sx.y) * (sy.x + sy.y));
}
#else
// trilinear: the level whose texels match the footprint's size rho (texels per pixel), the
// root mean square of its two sides: an isotropic filter as wide in variance as the
// footprint (footprint.LOD_BIAS). Chosen here, not by the sampler: GPUs approximate the
// footprint their own way (an NVIDIA H200's gave 18 % fewer events than llvmpipe's).
// `point`: the texture has level 0 alone, so this is its bilinear read at the centre.
vec4 footprint_mean(sampler2DArray shading, vec2 texel_at, float layer, vec2 across, vec2 down)
{
    float rho2 = 0.5 * (dot(across, across) + dot(down, down));
    float level = 0.5 * log2(max(rho2, 1e-20)) + level_bias;
    return textureLod(shading, vec3((texel_at + 0.5) / texture_side, layer), level);
}
#endif
