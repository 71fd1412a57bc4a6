// Lanes: the number type the contact laws are written over. A law is one template over `R`, used
// with R = double (one contact: the row-by-row path, unit tests) and with R = Pack (kWidth contacts
// at once, one per lane: the batched force pass). Every branch of a law is a select, so that both
// widths run the same arithmetic in the same order.
//
// This header is the only SIMD code of the engine: the Pack type (GCC vector extensions, one AVX-512
// register with -march=native on this machine), its masks, the few functions a law needs beyond
// + − × ÷ (sqrt, select, exp where a mask is set), loads and stores, and the 8 × 8 transpose the
// force pass uses to move whole records into lanes and back.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__AVX512F__)
// (GCC 12 warns that the headers' _mm512_undefined_pd() "may be used uninitialized".)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop
#endif

#include "hilldem/core/vec3.hpp"

namespace hilldem::lanes {

inline constexpr std::size_t kWidth = 8;  // contacts per Pack
typedef double Pack __attribute__((vector_size(kWidth * sizeof(double))));
typedef std::int64_t PackMask __attribute__((vector_size(kWidth * sizeof(double))));  // lanes all 1s or 0

template <class R> struct MaskOf;
template <> struct MaskOf<double> { using type = bool; };
template <> struct MaskOf<Pack> { using type = PackMask; };
// What a comparison of two R gives: bool for double, a PackMask for a Pack.
template <class R> using Mask = typename MaskOf<R>::type;

// R with every lane x.
template <class R> HILLDEM_INLINE R splat(double x) {
  if constexpr (std::is_same_v<R, double>) return x;
  else return R{} + x;
}

HILLDEM_INLINE double select(bool m, double a, double b) { return m ? a : b; }
HILLDEM_INLINE Pack select(PackMask m, Pack a, Pack b) { return m ? a : b; }

// max(a, b) as std::max: b where a < b, else a (so a NaN b gives a).
template <class R> HILLDEM_INLINE R max(R a, R b) { return select(a < b, b, a); }
template <class R> HILLDEM_INLINE R min(R a, R b) { return select(b < a, b, a); }

HILLDEM_INLINE double sqrt(double x) { return std::sqrt(x); }
HILLDEM_INLINE Pack sqrt(Pack x) {
#if defined(__AVX512F__)
  const __m512d v = reinterpret_cast<__m512d>(x);
  return reinterpret_cast<Pack>(_mm512_mask_sqrt_pd(v, 0xFF, v));  // (the masked form: no undefined source operand)
#else
  Pack r;
  for (std::size_t i = 0; i < kWidth; ++i) r[i] = std::sqrt(x[i]);
  return r;
#endif
}

HILLDEM_INLINE bool any(bool m) { return m; }
HILLDEM_INLINE bool any(PackMask m) {
  std::int64_t bits = 0;
  for (std::size_t i = 0; i < kWidth; ++i) bits |= m[i];
  return bits != 0;
}

// exp(x) where m is set, 1 elsewhere. exp has no vector instruction, and a vector exp would round
// differently from std::exp: lane by lane, and only for the lanes that need it (wet contacts).
HILLDEM_INLINE double exp_where(bool m, double x) { return m ? std::exp(x) : 1.0; }
HILLDEM_INLINE Pack exp_where(PackMask m, Pack x) {
  Pack r = splat<Pack>(1.0);
  if (!any(m)) return r;
  for (std::size_t i = 0; i < kWidth; ++i)
    if (m[i]) r[i] = std::exp(x[i]);
  return r;
}

// 1.0 where m is set, else 0.0 (flags kept as doubles in the batch's lane columns).
HILLDEM_INLINE double flag(bool m) { return m ? 1.0 : 0.0; }
HILLDEM_INLINE Pack flag(PackMask m) { return select(m, splat<Pack>(1.0), splat<Pack>(0.0)); }

HILLDEM_INLINE Pack load(const double* p) {
  Pack v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
HILLDEM_INLINE void store(double* p, Pack v) { std::memcpy(p, &v, sizeof v); }

// A 3-vector of R: of one contact, or of kWidth contacts lane by lane.
template <class R> struct V3 {
  R x, y, z;
};
template <class R> HILLDEM_INLINE V3<R> operator+(const V3<R>& a, const V3<R>& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class R> HILLDEM_INLINE V3<R> operator-(const V3<R>& a, const V3<R>& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class R> HILLDEM_INLINE V3<R> operator*(const V3<R>& a, std::type_identity_t<R> s) { return {a.x * s, a.y * s, a.z * s}; }
template <class R> HILLDEM_INLINE R dot(const V3<R>& a, const V3<R>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class R> HILLDEM_INLINE V3<R> cross(const V3<R>& a, const V3<R>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class R> HILLDEM_INLINE R norm2(const V3<R>& a) { return dot(a, a); }
template <class R> HILLDEM_INLINE R norm(const V3<R>& a) { return sqrt(norm2(a)); }
template <class R> HILLDEM_INLINE V3<R> select(Mask<R> m, const V3<R>& a, const V3<R>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

HILLDEM_INLINE V3<double> v3(const Vec3& v) { return {v.x, v.y, v.z}; }
// v in every lane.
template <class R> HILLDEM_INLINE V3<R> splat3(const Vec3& v) { return {splat<R>(v.x), splat<R>(v.y), splat<R>(v.z)}; }
HILLDEM_INLINE Vec3 vec3(const V3<double>& v) { return {v.x, v.y, v.z}; }
// Three lane columns from `x`, `y`, `z` at lane i (a whole Pack from there).
HILLDEM_INLINE V3<Pack> load3(const double* x, const double* y, const double* z, std::size_t i) {
  return {load(x + i), load(y + i), load(z + i)};
}
HILLDEM_INLINE void store3(double* x, double* y, double* z, std::size_t i, const V3<Pack>& v) {
  store(x + i, v.x), store(y + i, v.y), store(z + i, v.z);
}

#if defined(__AVX512F__)
// Eight 32-bit lane indices (a batch's slots or balls) from p, as eight 64-bit lanes.
HILLDEM_INLINE __m512i widen8(const std::uint32_t* p) {
  return _mm512_cvtepu32_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
}
// The 8 x 8 transpose of doubles: r[i] holds lane i's eight fields, c[j] field j of the eight lanes
// (unpack pairs of lanes, then pairs of pairs, then the two halves).
HILLDEM_INLINE void transpose8(const __m512d r[8], __m512d c[8]) {
  __m512d t[8], u[8];
  for (int k = 0; k < 4; ++k) {
    t[2 * k] = _mm512_unpacklo_pd(r[2 * k], r[2 * k + 1]);      // fields 0 2 4 6 of two lanes
    t[2 * k + 1] = _mm512_unpackhi_pd(r[2 * k], r[2 * k + 1]);  // fields 1 3 5 7
  }
  const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  for (int k = 0; k < 2; ++k) {  // lanes 0-3 (k = 0) and 4-7 (k = 1)
    u[4 * k + 0] = _mm512_permutex2var_pd(t[4 * k + 0], lo, t[4 * k + 2]);  // fields 0 | 4 of four lanes
    u[4 * k + 1] = _mm512_permutex2var_pd(t[4 * k + 0], hi, t[4 * k + 2]);  // 2 | 6
    u[4 * k + 2] = _mm512_permutex2var_pd(t[4 * k + 1], lo, t[4 * k + 3]);  // 1 | 5
    u[4 * k + 3] = _mm512_permutex2var_pd(t[4 * k + 1], hi, t[4 * k + 3]);  // 3 | 7
  }
  c[0] = _mm512_shuffle_f64x2(u[0], u[4], 0x44), c[4] = _mm512_shuffle_f64x2(u[0], u[4], 0xEE);
  c[2] = _mm512_shuffle_f64x2(u[1], u[5], 0x44), c[6] = _mm512_shuffle_f64x2(u[1], u[5], 0xEE);
  c[1] = _mm512_shuffle_f64x2(u[2], u[6], 0x44), c[5] = _mm512_shuffle_f64x2(u[2], u[6], 0xEE);
  c[3] = _mm512_shuffle_f64x2(u[3], u[7], 0x44), c[7] = _mm512_shuffle_f64x2(u[3], u[7], 0xEE);
}
#endif

}  // namespace hilldem::lanes
