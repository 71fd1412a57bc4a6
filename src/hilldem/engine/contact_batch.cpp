#include "hilldem/engine/contact_batch.hpp"

#include <algorithm>
#include <cmath>

#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"

namespace hilldem {

namespace {

// A lane's 3-vector, read from or written to three columns.
struct Cols {
  double* __restrict x;
  double* __restrict y;
  double* __restrict z;
  HILLDEM_INLINE Vec3 get(std::size_t i) const { return {x[i], y[i], z[i]}; }
  HILLDEM_INLINE void set(std::size_t i, const Vec3& v) const { x[i] = v.x, y[i] = v.y, z[i] = v.z; }
};

Cols cols(ContactBatch& b, ContactBatch::Field first) {
  return {b.col(first), b.col(static_cast<ContactBatch::Field>(first + 1)), b.col(static_cast<ContactBatch::Field>(first + 2))};
}

// Geometry (Eqs. 2-3) of every lane; coincident centres keep the old normal.
void batch_geometry(ContactBatch& batch, std::size_t n) {
  using F = ContactBatch;
  const Cols d = cols(batch, F::kDx), n_old = cols(batch, F::kNox), n_new = cols(batch, F::kNx);
  const double* __restrict r1 = batch.col(F::kR1);
  const double* __restrict r2 = batch.col(F::kR2);
  double* __restrict gap = batch.col(F::kGap);
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const double x = d.x[i], y = d.y[i], z = d.z[i];
    const double dist = std::sqrt(x * x + y * y + z * z);
    const bool apart = dist > 0.0;
    n_new.x[i] = apart ? x / dist : n_old.x[i];
    n_new.y[i] = apart ? y / dist : n_old.y[i];
    n_new.z[i] = apart ? z / dist : n_old.z[i];
    gap[i] = dist - (r1[i] + r2[i]);
  }
}

// What every law reads of a lane besides its parameters.
struct LaneInputs {
  Cols n_new, n_old, s_old, va, vb, wa, wb;
  const double* __restrict r1;
  const double* __restrict r2;
  const double* __restrict gap;
  explicit LaneInputs(ContactBatch& b)
      : n_new(cols(b, ContactBatch::kNx)), n_old(cols(b, ContactBatch::kNox)), s_old(cols(b, ContactBatch::kSx)),
        va(cols(b, ContactBatch::kVax)), vb(cols(b, ContactBatch::kVbx)), wa(cols(b, ContactBatch::kWax)),
        wb(cols(b, ContactBatch::kWbx)), r1(b.col(ContactBatch::kR1)), r2(b.col(ContactBatch::kR2)),
        gap(b.col(ContactBatch::kGap)) {}
};

// Lane i's relative velocity at the contact point split into normal and shear rates (§1.2:
// ẋ_c(2) − ẋ_c(1), ẋ_c(1) = v1 + ω1 × (R1 + g/2) n̂, ẋ_c(2) = v2 − ω2 × (R2 + g/2) n̂), and its stored
// shear force carried into the current plane (PlaneRotation::carry, §1.3: (a) tilt n_old × n̂,
// (b) twist n̂ ½(ω1 + ω2)·n̂ Δt, (c) the normal part dropped and the magnitude restored). In
// components, every branch a select, so that the callers' loops vectorise (GCC 12 gives up on
// selects between Vec3 temporaries).
struct LaneMotion {
  double normal_rate;  // δ̇_n [m/s], > 0 apart
  double srx, sry, srz;  // δ̇_s [m/s]
  double cx, cy, cz;     // stored shear force in the current plane [N]
};

HILLDEM_INLINE LaneMotion lane_motion(const LaneInputs& in, std::size_t i, double dt) {
  const double nx = in.n_new.x[i], ny = in.n_new.y[i], nz = in.n_new.z[i];
  const double g = in.gap[i];
  const double wax = in.wa.x[i], way = in.wa.y[i], waz = in.wa.z[i];
  const double wbx = in.wb.x[i], wby = in.wb.y[i], wbz = in.wb.z[i];
  const double arm1 = in.r1[i] + 0.5 * g, arm2 = in.r2[i] + 0.5 * g;
  const double ax = nx * arm1, ay = ny * arm1, az = nz * arm1;
  const double bx = nx * arm2, by = ny * arm2, bz = nz * arm2;
  const double v1x = in.va.x[i] + (way * az - waz * ay);
  const double v1y = in.va.y[i] + (waz * ax - wax * az);
  const double v1z = in.va.z[i] + (wax * ay - way * ax);
  const double v2x = in.vb.x[i] - (wby * bz - wbz * by);
  const double v2y = in.vb.y[i] - (wbz * bx - wbx * bz);
  const double v2z = in.vb.z[i] - (wbx * by - wby * bx);
  const double rx = v2x - v1x, ry = v2y - v1y, rz = v2z - v1z;
  const double ox = in.n_old.x[i], oy = in.n_old.y[i], oz = in.n_old.z[i];
  const double tx = oy * nz - oz * ny, ty = oz * nx - ox * nz, tz = ox * ny - oy * nx;
  const double spin = 0.5 * ((wax + wbx) * nx + (way + wby) * ny + (waz + wbz) * nz) * dt;
  const double qx = nx * spin, qy = ny * spin, qz = nz * spin;
  const double sx = in.s_old.x[i], sy = in.s_old.y[i], sz = in.s_old.z[i];
  const double mag2 = sx * sx + sy * sy + sz * sz;
  const double g1x = sx - (sy * tz - sz * ty), g1y = sy - (sz * tx - sx * tz), g1z = sz - (sx * ty - sy * tx);
  double gx = g1x - (g1y * qz - g1z * qy), gy = g1y - (g1z * qx - g1x * qz), gz = g1z - (g1x * qy - g1y * qx);
  const double gn = gx * nx + gy * ny + gz * nz;
  gx = gx - nx * gn, gy = gy - ny * gn, gz = gz - nz * gn;
  const double g2 = gx * gx + gy * gy + gz * gz;
  const double scale = g2 > 0.0 ? std::sqrt(mag2 / g2) : 1.0;
  const double normal_rate = rx * nx + ry * ny + rz * nz;
  return {normal_rate,
          rx - nx * normal_rate,
          ry - ny * normal_rate,
          rz - nz * normal_rate,
          mag2 == 0.0 ? sx : gx * scale,
          mag2 == 0.0 ? sy : gy * scale,
          mag2 == 0.0 ? sz : gz * scale};
}

// What every law writes of a lane besides the stiffnesses and the rupture flag.
struct LaneOutputs {
  Cols force, shear;
  double* __restrict normal_force;
  double* __restrict moisture_force;
  double* __restrict trial;
  double* __restrict active;
  explicit LaneOutputs(ContactBatch& b)
      : force(cols(b, ContactBatch::kFx)), shear(cols(b, ContactBatch::kShx)), normal_force(b.col(ContactBatch::kFn)),
        moisture_force(b.col(ContactBatch::kFm)), trial(b.col(ContactBatch::kTrial)), active(b.col(ContactBatch::kActive)) {}
};

// Lane i's results: F_c = (normal part) n̂ + F_s, and the shear force h carried to the next step. An
// inactive contact gives no force and forgets its shear force (hill Eq. 16 with F^μ_s = 0; linear §3).
HILLDEM_INLINE void store_lane(const LaneOutputs& o, std::size_t i, bool active, double nx, double ny, double nz,
                               double normal_part, double fsx, double fsy, double fsz, double hx, double hy, double hz,
                               double fn, double fm, double trial) {
  o.force.x[i] = active ? nx * normal_part + fsx : 0.0;
  o.force.y[i] = active ? ny * normal_part + fsy : 0.0;
  o.force.z[i] = active ? nz * normal_part + fsz : 0.0;
  o.shear.x[i] = active ? hx : 0.0, o.shear.y[i] = active ? hy : 0.0, o.shear.z[i] = active ? hz : 0.0;
  o.normal_force[i] = active ? fn : 0.0;
  o.moisture_force[i] = active ? fm : 0.0;
  o.trial[i] = active ? trial : 0.0;
  o.active[i] = active ? 1.0 : 0.0;
}

}  // namespace

std::size_t ContactBatch::pad_lanes() {
  static_assert(kLanes % kVector == 0);
  const std::size_t padded = padded_size();  // (0 for an empty batch)
  for (int f = 0; f < kKn; ++f)  // the inputs
    for (std::size_t lane = size_; lane < padded; ++lane) data_[f][lane] = data_[f][size_ - 1];
  return padded;
}

void ContactBatch::pad_geometry(std::size_t padded) {
  for (int f : {kNx, kNy, kNz, kGap})
    for (std::size_t lane = size_; lane < padded; ++lane) data_[f][lane] = data_[f][size_ - 1];
}

void hill_batch_forces(ContactBatch& batch, double dt, bool want_stiffness) {
  using F = ContactBatch;
  const std::size_t n = batch.pad_lanes();
  const Cols n_new = cols(batch, F::kNx);
  const double* __restrict r1 = batch.col(F::kR1);
  const double* __restrict r2 = batch.col(F::kR2);
  double* __restrict kn = batch.col(F::kKn);
  double* __restrict ks = batch.col(F::kKs);
  double* __restrict bn = batch.col(F::kBn);
  double* __restrict bs = batch.col(F::kBs);
  double* __restrict ro = batch.col(F::kRo);
  const double* __restrict fric = batch.col(F::kFric);
  const double* __restrict suction = batch.col(F::kSuction);
  const double* __restrict damp = batch.col(F::kDamp);
  const double* __restrict wet = batch.col(F::kWet);
  double* __restrict gap = batch.col(F::kGap);
  double* __restrict fm_out = batch.col(F::kFm);
  double* __restrict ruptured = batch.col(F::kRuptured);
  double* __restrict k_tran = batch.col(F::kKtran);
  double* __restrict k_shear = batch.col(F::kKshear);

  // 0. The mapping of each contact (hill_mapping, spec §2.4), from the sums of the per-ball terms.
  {
    const double* __restrict ir = batch.col(F::kIr);
    const double* __restrict im = batch.col(F::kIm);
    const double* __restrict cn = batch.col(F::kCn);
    const double* __restrict cs = batch.col(F::kCs);
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      const HillMapping m = hill_mapping_of_sums(HillParams{0.0, damp[i], 0.0}, HillBodyTerms{ir[i], im[i], cn[i], cs[i]},
                                                 std::min(r1[i], r2[i]));
      kn[i] = m.kn, ks[i] = m.ks, bn[i] = m.bn, bs[i] = m.bs, ro[i] = m.r_o;
    }
  }

  batch_geometry(batch, n);

  // 2. Moisture (Eq. 12): the bridge force or its rupture, for wet lanes only (exp does not vectorise
  // without relaxing the math library's accuracy).
  for (std::size_t i = 0; i < n; ++i) {
    fm_out[i] = 0.0;
    ruptured[i] = 0.0;
    if (wet[i] == 0.0) continue;
    if (gap[i] >= hill_rupture_gap(ro[i])) ruptured[i] = 1.0;
    else fm_out[i] = hill_moisture_force(suction[i], ro[i], gap[i]);
  }

  // 3. Kinematics (§1.2), plane rotation (§1.3) and the law (Eqs. 13-18, 19-21), written out in
  // components with every branch a select, so that the loops vectorise. In two loops: the law's
  // last part (Eqs. 16-18: |F^h_s|, its clamp, |F^h_s + F^d_s| and the slip) is a chain of two
  // square roots and two divisions, each waiting for the one before. In one loop of ≈ 200
  // instructions the core could not start the next eight lanes' chain before this one ended; split,
  // the chains of several vectors run at once. Each lane's arithmetic is unchanged (same bits).
  const LaneInputs in(batch);
  const LaneOutputs out(batch);
  // Between the loops, per lane: F^h*_s before the clamp (Eq. 15), the shear rate δ̇_s, the shear
  // dashpot's −β_s (g_c)^¼ (Eq. 17), the strength μ F^s_n, F^s_n and |F*_s| [N].
  alignas(64) double carry[10][ContactBatch::kLanes];
  double* __restrict hx_ = carry[0];
  double* __restrict hy_ = carry[1];
  double* __restrict hz_ = carry[2];
  double* __restrict srx_ = carry[3];
  double* __restrict sry_ = carry[4];
  double* __restrict srz_ = carry[5];
  double* __restrict dmp_ = carry[6];
  double* __restrict strength_ = carry[7];
  double* __restrict fn_ = carry[8];
  double* __restrict trial_ = carry[9];
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const double g = gap[i];
    // Active: wet, or overlapping (spec §2.5), and not ruptured this step. As a comparison of doubles,
    // not a bool combination, which GCC 12 will not vectorise.
    const bool active = (wet[i] + (g <= 0.0 ? 1.0 : 0.0)) * (1.0 - ruptured[i]) > 0.0;
    const LaneMotion mo = lane_motion(in, i, dt);
    const double normal_rate = mo.normal_rate;
    const double srx = mo.srx, sry = mo.sry, srz = mo.srz;
    const double cx = mo.cx, cy = mo.cy, cz = mo.cz;
    const double overlap = -g;
    const bool touching = overlap > 0.0;
    const double root2 = touching ? std::sqrt(overlap) : 0.0;
    const double root4 = std::sqrt(root2);
    const double fn = touching ? kn[i] * overlap * root2 + bn[i] * root4 * (-normal_rate) : 0.0;
    // Eqs. 14-15, 17.
    const double strength = std::max(0.0, fric[i] * fn);
    const double dmp = -bs[i] * root4;
    const double dx = srx * dmp, dy = sry * dmp, dz = srz * dmp;
    const double inc = ks[i] * root2 * dt;
    const double hx = cx - srx * inc, hy = cy - sry * inc, hz = cz - srz * inc;
    const double ux = hx + dx, uy = hy + dy, uz = hz + dz;
    trial_[i] = std::sqrt(ux * ux + uy * uy + uz * uz);
    hx_[i] = hx, hy_[i] = hy, hz_[i] = hz;
    srx_[i] = srx, sry_[i] = sry, srz_[i] = srz;
    dmp_[i] = dmp, strength_[i] = strength, fn_[i] = fn;
    if (want_stiffness) {  // Eqs. 19-21 (hill_timestep_stiffness)
      const double ov = overlap <= 0.0 ? kHillTimestepOverlapFactor * ro[i] : overlap;
      const double sr = std::sqrt(ov);
      const double xi = damp[i] / 2.0;
      const double f = std::sqrt(1.0 + xi * xi) - xi;
      const double f2 = damp[i] > 0.0 ? f * f : 1.0;
      const double skn = damp[i] > 0.0 ? 1.5 * kn[i] * sr / f2 : 1.5 * kn[i] * sr;
      const double sks = damp[i] > 0.0 ? ks[i] * sr / f2 : ks[i] * sr;
      k_tran[i] = active ? skn + sks : 0.0;
      k_shear[i] = active ? sks : 0.0;
    }
  }
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const double nx = n_new.x[i], ny = n_new.y[i], nz = n_new.z[i];
    const double g = gap[i];
    const bool active = (wet[i] + (g <= 0.0 ? 1.0 : 0.0)) * (1.0 - ruptured[i]) > 0.0;
    const bool touching = -g > 0.0;
    const double strength = strength_[i];
    const double dmp = dmp_[i];
    const double dx = srx_[i] * dmp, dy = sry_[i] * dmp, dz = srz_[i] * dmp;
    double hx = hx_[i], hy = hy_[i], hz = hz_[i];
    // Eqs. 16-18.
    const double hm_mag = std::sqrt(hx * hx + hy * hy + hz * hz);
    const double clamp = hm_mag > strength ? (hm_mag > 0.0 ? strength / hm_mag : 0.0) : 1.0;
    hx = hm_mag > strength ? hx * clamp : hx;
    hy = hm_mag > strength ? hy * clamp : hy;
    hz = hm_mag > strength ? hz * clamp : hz;
    const double ex = hx + dx, ey = hy + dy, ez = hz + dz;
    const double t_mag = std::sqrt(ex * ex + ey * ey + ez * ez);
    const double slip = t_mag <= strength ? 1.0 : strength / t_mag;
    const double fsx = touching ? (t_mag <= strength ? ex : ex * slip) : 0.0;
    const double fsy = touching ? (t_mag <= strength ? ey : ey * slip) : 0.0;
    const double fsz = touching ? (t_mag <= strength ? ez : ez * slip) : 0.0;
    const double fn = fn_[i];
    const double fm = fm_out[i];
    store_lane(out, i, active, nx, ny, nz, fn + fm, fsx, fsy, fsz, hx, hy, hz, fn, fm, trial_[i]);
  }
}

void linear_batch_forces(ContactBatch& batch, double dt, bool want_stiffness, bool geometry_given) {
  using F = ContactBatch;
  const std::size_t n = batch.pad_lanes();
  if (geometry_given) batch.pad_geometry(n);
  else batch_geometry(batch, n);
  const Cols n_new = cols(batch, F::kNx);
  const double* __restrict kn = batch.col(F::kIr);
  const double* __restrict ks = batch.col(F::kIm);
  const double* __restrict fric = batch.col(F::kFric);
  const double* __restrict gap = batch.col(F::kGap);
  double* __restrict ruptured = batch.col(F::kRuptured);
  double* __restrict k_tran = batch.col(F::kKtran);
  double* __restrict k_shear = batch.col(F::kKshear);
  // Kinematics (§1.2), plane rotation (§1.3) and the linear law (§3), in components (see above).
  const LaneInputs in(batch);
  const LaneOutputs out(batch);
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const double nx = n_new.x[i], ny = n_new.y[i], nz = n_new.z[i];
    const double g = gap[i];
    const bool active = g < 0.0;  // overlapping; no tension, no reference gap
    const LaneMotion mo = lane_motion(in, i, dt);
    const double srx = mo.srx, sry = mo.sry, srz = mo.srz;
    const double cx = mo.cx, cy = mo.cy, cz = mo.cz;
    const double fn = kn[i] * -g;
    const double inc = ks[i] * dt;
    const double ux = cx - srx * inc, uy = cy - sry * inc, uz = cz - srz * inc;
    const double limit = fric[i] * fn;
    const double mag = std::sqrt(ux * ux + uy * uy + uz * uz);
    const double clamp = mag <= limit ? 1.0 : limit / mag;
    const double fsx = mag <= limit ? ux : ux * clamp;
    const double fsy = mag <= limit ? uy : uy * clamp;
    const double fsz = mag <= limit ? uz : uz * clamp;
    store_lane(out, i, active, nx, ny, nz, fn, fsx, fsy, fsz, fsx, fsy, fsz, fn, 0.0, mag);
    ruptured[i] = 0.0;
    if (want_stiffness) {
      k_tran[i] = active ? kn[i] + ks[i] : 0.0;
      k_shear[i] = active ? ks[i] : 0.0;
    }
  }
}

void batch_shares(ContactBatch& batch, double proximity) {
  using F = ContactBatch;
  const std::size_t n = batch.padded_size();  // (filled by the law's pad_lanes)
  const LaneInputs in(batch);    // n̂_c, the radii, the gap
  const LaneOutputs out(batch);  // F_c, the active flag
  const Cols ma = cols(batch, F::kMax), mb = cols(batch, F::kMbx);
  double* __restrict quick = batch.col(F::kQuick);
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const double nx = in.n_new.x[i], ny = in.n_new.y[i], nz = in.n_new.z[i];
    const double fx = out.force.x[i], fy = out.force.y[i], fz = out.force.z[i];
    const double g = in.gap[i];
    // n̂ × F_c, then times −(R + g/2): the arithmetic of Simulation::store_row, bit for bit.
    const double tx = ny * fz - nz * fy, ty = nz * fx - nx * fz, tz = nx * fy - ny * fx;
    const double arm1 = in.r1[i] + 0.5 * g, arm2 = in.r2[i] + 0.5 * g;
    ma.x[i] = tx * -arm1, ma.y[i] = ty * -arm1, ma.z[i] = tz * -arm1;
    mb.x[i] = tx * -arm2, mb.y[i] = ty * -arm2, mb.z[i] = tz * -arm2;
    const double sum = fx + fy + fz;
    // Finite: sum − sum is 0 (NaN for ±inf and NaN). Kept as a sum of doubles, not a bool
    // combination, which GCC 12 will not vectorise.
    const double kept = out.active[i] + (g <= proximity ? 1.0 : 0.0);
    const double finite = sum - sum == 0.0 ? 1.0 : 0.0;
    quick[i] = kept > 0.0 ? finite : 0.0;
  }
}

}  // namespace hilldem
