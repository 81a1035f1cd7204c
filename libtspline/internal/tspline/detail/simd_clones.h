#pragma once
// Internal to libtspline: TSPLINE_SIMD_CLONES before a function compiles it
// twice, for x86-64-v3 (AVX2, FMA) and for the baseline, and the loader picks
// the one the processor runs (GCC/Clang function multiversioning); with
// `flatten`, so that what it calls is inlined and compiled for that target too.
// Not under the sanitizers, and only the baseline elsewhere.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#if defined(__has_feature)
#if !__has_feature(address_sanitizer) && !__has_feature(memory_sanitizer) && !__has_feature(thread_sanitizer)
#define TSPLINE_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v3", "default"), flatten))
#endif
#else
#define TSPLINE_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v3", "default"), flatten))
#endif
#endif
#ifndef TSPLINE_SIMD_CLONES
#define TSPLINE_SIMD_CLONES __attribute__((flatten))
#endif
