// shaders/patch_displaced.h (GLSL only; include after shared.h, draw_params.h and patch_buffers.h, with its block
// MaxDisplacement: define PC_MAX_DISPLACEMENT readonly): which patches the draw displaces,
// shared by patch.tese.glsl (displacement) and patch.frag.glsl (one-sided drawing).
// With a displacement map (u_displace) a patch is displaced unless the per-patch margins are given
// (u_has_margins) and its margin is 0: a margin bounds |D| over the patch, so a zero margin means
// D = 0 there, and leaving it undisplaced changes nothing but lets scenes mix displaced and plain
// objects under one map (the plain ones get margin 0). A displaced patch is drawn two-sided; the
// others follow u_discard_back_facing.

#ifndef PC_MAX_DISPLACEMENT
#error patch_displaced.h needs patch_buffers.h's MaxDisplacement (PC_MAX_DISPLACEMENT)
#endif

bool patch_is_displaced(uint p) { return u_displace && (!u_has_margins || max_displacement[p] > 0.0); }
