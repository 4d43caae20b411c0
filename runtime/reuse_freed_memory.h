// A render of many frames allocates and frees the denoiser's planes (about
// 20 MB at 320x180) every frame. glibc's malloc returns such memory to the
// system when it is freed (the heap's top trimmed, large blocks unmapped),
// so every frame faulted its pages in again: 5,300 page faults and about
// 10 CPU ms a frame with nlr-fast, a quarter of the filter's own time
// (bench/results/anim_denoise.md). This keeps freed memory in the process
// for the next frame instead. Images are unchanged; only the allocator's
// thresholds move. A no-op where the C library is not glibc.
#pragma once

namespace sdfc {

// Call once, before the frames: the process then keeps up to 512 MB of freed
// memory for reuse.
void reuseFreedMemory();

}  // namespace sdfc
