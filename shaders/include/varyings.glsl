// Which per-vertex values a variant interpolates: each varying costs llvmpipe a plane
// equation per triangle, so only the needed ones exist.
//   NEEDS_OBJ:     object-space point (textures, bump and opacity maps)
//   NEEDS_SURFACE: world point and shading normal per fragment (Phong lighting, environment
//                  reflection)
#if defined(TEX_KIND) || defined(BUMP_KIND) || defined(OPACITY_KIND)
#define NEEDS_OBJ
#endif
#if defined(MODE_PHONG) || defined(ENV_MAP)
#define NEEDS_SURFACE
#endif
// stand-in shadows (standins.glsl) test the world point per fragment, in Gouraud too
#if defined(SHADOW_MAPS) && !defined(NEEDS_SURFACE)
#define NEEDS_SURFACE
#endif
