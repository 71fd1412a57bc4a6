// hilldem_lean_reference: how fast one core can step the bench bed with the hill model's dry physics
// when the data are as lean as they can be. A measuring stick for issue #4 (docs/performance.md,
// "A lean reference kernel"), not part of the engine: nothing here is used by hilldem.
//
// The bed and physics of `hilldem bench` (bench/bed_settled.data replicated r x r, periodic in x and
// y, gravity, dt = 1e-6 s, no local damping; between grains the dry hill law: Hertz-Mindlin springs
// with Tsuji dashpots, E 29 GPa, nu 0.15, damp_con 0.07, the incremental shear force carried into the
// contact plane (tilt and twist, spec §1.3) and clamped by Coulomb friction mu 0.4), with two
// differences: the floor is a frictionless linear spring (k_n = pi R E*, as hilldem's linear floor
// but without shear), and the neighbour list is built once (the bed at rest: hilldem rebuilds it 0
// times in these runs too). What makes it lean:
//   - per ball, a 64-byte record (position, radius, velocity, 1/m) and a 32-byte one (spin, 1/R) that
//     the law of motion updates in place, and forces and moments accumulated by the pair loop itself
//     (both balls of a pair, in row order: no per-row output, no collection pass);
//   - per neighbour pair, a 4-byte index and a 1-byte periodic image (CSR half list), and 48 bytes of
//     history (last normal, shear force) next to it; nothing reported, no per-pair parameters or flags;
//   - in the batched mode, the records of the neighbour 16 rows on asked for ahead, as hilldem's pair
//     loop does (1.2-1.6 x at 100,800 spheres, eighth session).
// The law: row by row (mode 0: one contact's chain of square roots and divisions at a time, as
// LAMMPS does), or over lanes of 64 touching pairs (mode 1: gather, a vectorised law, scatter, as
// hilldem's ContactBatch). Modes 1 + flags add hilldem's costs back, one at a time:
//   +2 late:    each row's force and moment on its second ball in per-row columns (48 B), summed per
//               ball by a collection pass over its rows (hilldem's two halves of the force sum);
//   +4 report:  gap, F_n, F^m, |F*_s| (8 B each), F_c (24 B) and two flag bytes written per contact;
//   +8 rowmeta: a 12-byte key, exists and model bytes and 24 B of parameters read per row;
//   +16 copy:   the ball state kept in separate columns and copied into the records every step.
// and one that takes a cost away:
//   +32 nobranch: no branch on whether a pair touches: every row's fields are written into the next
//               lane's slot, which becomes a lane only if the pair touches (as hilldem's row loop on
//               large beds). 1.16-1.29 x at 11,200 spheres, where the branch predictor no longer
//               learns which rows touch; 1.02-1.03 x in cache, 0.93-1.02 x at 100,800 (thirteenth
//               session, docs/performance.md).
//
// Usage: hilldem_lean_reference DATA [replicate=1] [steps=1000] [mode=1]
// Prints one line like `hilldem bench`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

struct alignas(64) Kin {
  double x, y, z, r;
  double vx, vy, vz, inv_m;
};
struct alignas(32) Spin {
  double wx, wy, wz, inv_r;
};
struct Acc {
  double fx, fy, fz, tx, ty, tz;
};
struct History {
  double nx, ny, nz, hx, hy, hz;
};

// The dry hill law of one touching pair (spec §1.1-1.3, hill Eqs. 13-18 with F^m = 0), every branch a
// select so that the batched mode's lane loop vectorises it; the row-by-row mode calls it per pair.
struct PairIn {
  double dx, dy, dz, ra, rb;             // x_b − x_a [m], radii [m]
  double vax, vay, vaz, vbx, vby, vbz;   // velocities [m/s]
  double wax, way, waz, wbx, wby, wbz;   // spins [rad/s]
  double ira, irb, ima, imb;             // 1/R [1/m], 1/m [1/kg]
  double nox, noy, noz, hx, hy, hz;      // last normal, shear force [N]
};
struct PairOut {
  double nx, ny, nz, hx, hy, hz;  // normal, shear force carried to the next step [N]
  double fx, fy, fz;              // force on b [N]
  double arm1, arm2;              // R + g/2 of a and b [m]
};
struct LawConstants {
  double c_kn, c_ks, gamma, mu, dt;
};
static inline __attribute__((always_inline)) PairOut pair_law(const PairIn& p, const LawConstants& k) {
  const double dist = std::sqrt(p.dx * p.dx + p.dy * p.dy + p.dz * p.dz), inv = 1 / dist;
  const double nx = p.dx * inv, ny = p.dy * inv, nz = p.dz * inv;
  const double overlap = p.ra + p.rb - dist;
  const double arm1 = p.ra - 0.5 * overlap, arm2 = p.rb - 0.5 * overlap;
  // relative velocity at the contact point
  const double ax = nx * arm1, ay = ny * arm1, az = nz * arm1, bx = nx * arm2, by = ny * arm2, bz = nz * arm2;
  const double v1x = p.vax + (p.way * az - p.waz * ay), v1y = p.vay + (p.waz * ax - p.wax * az),
               v1z = p.vaz + (p.wax * ay - p.way * ax);
  const double v2x = p.vbx - (p.wby * bz - p.wbz * by), v2y = p.vby - (p.wbz * bx - p.wbx * bz),
               v2z = p.vbz - (p.wbx * by - p.wby * bx);
  const double rx = v2x - v1x, ry = v2y - v1y, rz = v2z - v1z;
  const double vn = rx * nx + ry * ny + rz * nz;
  const double sx = rx - nx * vn, sy = ry - ny * vn, sz = rz - nz * vn;
  // mapping (Table 4)
  const double re = 1 / (p.ira + p.irb), me = 1 / (p.ima + p.imb);
  const double sre = std::sqrt(re), kn = k.c_kn * sre, ks = k.c_ks * sre;
  const double bn = k.gamma * std::sqrt(me * kn), bs = k.gamma * std::sqrt(me * ks);
  // the stored shear force carried into the current plane: tilt, twist, normal part dropped, magnitude kept
  const double mag2 = p.hx * p.hx + p.hy * p.hy + p.hz * p.hz;
  const double tx = p.noy * nz - p.noz * ny, ty = p.noz * nx - p.nox * nz, tz = p.nox * ny - p.noy * nx;
  const double spin_n = 0.5 * ((p.wax + p.wbx) * nx + (p.way + p.wby) * ny + (p.waz + p.wbz) * nz) * k.dt;
  const double qx = nx * spin_n, qy = ny * spin_n, qz = nz * spin_n;
  const double g1x = p.hx - (p.hy * tz - p.hz * ty), g1y = p.hy - (p.hz * tx - p.hx * tz),
               g1z = p.hz - (p.hx * ty - p.hy * tx);
  double gx = g1x - (g1y * qz - g1z * qy), gy = g1y - (g1z * qx - g1x * qz), gz = g1z - (g1x * qy - g1y * qx);
  const double gn = gx * nx + gy * ny + gz * nz;
  gx -= nx * gn, gy -= ny * gn, gz -= nz * gn;
  const double g2 = gx * gx + gy * gy + gz * gz;
  const double sc = g2 > 0 ? std::sqrt(mag2 / g2) : 1.0;
  double hx = mag2 > 0 ? gx * sc : p.hx, hy = mag2 > 0 ? gy * sc : p.hy, hz = mag2 > 0 ? gz * sc : p.hz;
  // Hertz-Mindlin with Tsuji dashpots, incremental shear, Coulomb clamp
  const double root2 = std::sqrt(overlap), root4 = std::sqrt(root2);
  const double fn = kn * overlap * root2 - bn * root4 * vn;
  const double strength = std::max(0.0, k.mu * fn);
  const double inc = ks * root2 * k.dt;
  hx -= sx * inc, hy -= sy * inc, hz -= sz * inc;
  const double hm = std::sqrt(hx * hx + hy * hy + hz * hz);
  const double c1 = hm > strength ? (hm > 0 ? strength / hm : 0.0) : 1.0;
  hx *= c1, hy *= c1, hz *= c1;
  const double dmp = -bs * root4;
  const double ex0 = hx + sx * dmp, ey0 = hy + sy * dmp, ez0 = hz + sz * dmp;
  const double tm = std::sqrt(ex0 * ex0 + ey0 * ey0 + ez0 * ez0);
  const double c2 = tm > strength ? strength / tm : 1.0;
  return {nx, ny, nz, hx, hy, hz, nx * fn + ex0 * c2, ny * fn + ey0 * c2, nz * fn + ez0 * c2, arm1, arm2};
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: hilldem_lean_reference DATA [replicate=1] [steps=1000] [mode=1]\n");
    return 2;
  }
  const int rep = argc > 2 ? std::atoi(argv[2]) : 1;
  const long steps = argc > 3 ? std::atol(argv[3]) : 1000;
  if (rep < 1 || rep > 20 || steps < 1) {
    std::fprintf(stderr, "replicate must be in [1, 20] and steps >= 1\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "%s: cannot open the data file\n", argv[1]);
    return 2;
  }
  std::string line;
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  struct Ball {
    double x, y, z, r, rho;
  };
  std::vector<Ball> src;
  bool atoms = false;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    if (line.find("xlo xhi") != std::string::npos) s >> lo[0] >> hi[0];
    else if (line.find("ylo yhi") != std::string::npos) s >> lo[1] >> hi[1];
    else if (line.find("zlo zhi") != std::string::npos) s >> lo[2] >> hi[2];
    else if (line.rfind("Atoms", 0) == 0) atoms = true;
    else if (atoms) {
      long id;
      int type;
      double d, rho, x, y, z;
      if (s >> id >> type >> d >> rho >> x >> y >> z) src.push_back({x, y, z, d / 2, rho});
    }
  }
  const double lx = hi[0] - lo[0], ly = hi[1] - lo[1];
  std::vector<Ball> balls;
  for (int i = 0; i < rep; ++i)
    for (int j = 0; j < rep; ++j)
      for (const Ball& b : src) balls.push_back({b.x + i * lx, b.y + j * ly, b.z, b.r, b.rho});
  const double Lx = lx * rep, Ly = ly * rep;
  const std::size_t n = balls.size();
  // z-major cell order (as hilldem's sort_balls_spatially).
  double mean_r = 0;
  for (const Ball& b : balls) mean_r += b.r;
  mean_r /= n;
  const double cell = 2 * mean_r;
  const long cx = static_cast<long>(Lx / cell) + 1, cy = static_cast<long>(Ly / cell) + 1;
  auto key = [&](const Ball& b) {
    return (static_cast<long>(b.z / cell) * cy + static_cast<long>(b.y / cell)) * cx + static_cast<long>(b.x / cell);
  };
  std::stable_sort(balls.begin(), balls.end(), [&](const Ball& a, const Ball& b) { return key(a) < key(b); });

  std::vector<Kin> kin(n);
  std::vector<Spin> spin(n);
  std::vector<Acc> acc(n);
  std::vector<double> inv_i(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Ball& b = balls[i];
    const double m = b.rho * 4.0 / 3.0 * M_PI * b.r * b.r * b.r;
    kin[i] = {b.x, b.y, b.z, b.r, 0, 0, 0, 1 / m};
    spin[i] = {0, 0, 0, 1 / b.r};
    inv_i[i] = 1 / (0.4 * m * b.r * b.r);
  }
  // Half neighbour list within r_a + r_b + skin (brute force over cells of 2.5 mean radii... simple
  // grid with cell >= max reach).
  const double skin = 1e-3;
  double max_r = 0;
  for (const Ball& b : balls) max_r = std::max(max_r, b.r);
  const double reach_cell = 2 * max_r + skin;
  const long gx = std::max(1L, static_cast<long>(Lx / reach_cell)), gy = std::max(1L, static_cast<long>(Ly / reach_cell));
  double zmax = 0;
  for (const Ball& b : balls) zmax = std::max(zmax, b.z);
  const long gz = static_cast<long>(zmax / reach_cell) + 1;
  std::vector<std::vector<std::uint32_t>> grid(gx * gy * gz);
  auto gidx = [&](long i, long j, long k) { return (k * gy + j) * gx + i; };
  auto cell_of = [&](const Kin& k, long& i, long& j, long& l) {
    i = std::min(gx - 1, static_cast<long>(k.x / (Lx / gx)));
    j = std::min(gy - 1, static_cast<long>(k.y / (Ly / gy)));
    l = std::min(gz - 1, std::max(0L, static_cast<long>(k.z / reach_cell)));
  };
  for (std::size_t a = 0; a < n; ++a) {
    long i, j, l;
    cell_of(kin[a], i, j, l);
    grid[gidx(i, j, l)].push_back(static_cast<std::uint32_t>(a));
  }
  std::vector<std::uint32_t> start(n + 1, 0), nb;
  std::vector<std::uint8_t> image;  // 0..8: shift (ix, iy) in {-1, 0, 1}^2 of b
  {
    std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> lists(n);
    for (std::size_t a = 0; a < n; ++a) {
      long i, j, l;
      cell_of(kin[a], i, j, l);
      for (long dl = -1; dl <= 1; ++dl)
        for (long dj = -1; dj <= 1; ++dj)
          for (long di = -1; di <= 1; ++di) {
            const long L = l + dl;
            if (L < 0 || L >= gz) continue;
            const long I = (i + di + gx) % gx, J = (j + dj + gy) % gy;
            for (std::uint32_t b : grid[gidx(I, J, L)]) {
              if (b <= a) continue;
              double dx = kin[b].x - kin[a].x, dy = kin[b].y - kin[a].y;
              int ix = 0, iy = 0;
              if (dx > Lx / 2) ix = -1;
              if (dx < -Lx / 2) ix = 1;
              if (dy > Ly / 2) iy = -1;
              if (dy < -Ly / 2) iy = 1;
              dx += ix * Lx, dy += iy * Ly;
              const double dz = kin[b].z - kin[a].z;
              const double reach = kin[a].r + kin[b].r + skin;
              if (dx * dx + dy * dy + dz * dz > reach * reach) continue;
              const auto code = static_cast<std::uint8_t>((ix + 1) * 3 + (iy + 1));
              if (std::find_if(lists[a].begin(), lists[a].end(), [&](auto& p) { return p.first == b; }) == lists[a].end())
                lists[a].push_back({b, code});
            }
          }
      std::sort(lists[a].begin(), lists[a].end());
    }
    for (std::size_t a = 0; a < n; ++a) {
      start[a + 1] = start[a] + lists[a].size();
      for (auto& p : lists[a]) nb.push_back(p.first), image.push_back(p.second);
    }
  }
  const std::size_t pairs = nb.size();
  std::vector<History> hist(pairs, History{0, 0, 1, 0, 0, 0});
  double shift_x[9], shift_y[9];
  for (int c = 0; c < 9; ++c) shift_x[c] = (c / 3 - 1) * Lx, shift_y[c] = (c % 3 - 1) * Ly;

  // Hill constants (E 29 GPa, ν 0.15, μ 0.4, γ 0.07): per-ball terms are equal, so E_e = E / (2(1 − ν²)),
  // G_e = E / (4 (2 − ν)(1 + ν)); k_n = 4/3 E_e √R_e, k_s = 8 G_e √R_e, β = γ √(m_e k).
  const double E = 29e9, nu = 0.15, mu = 0.4, gamma = 0.07, dt = 1e-6;
  const double Ee = E / (2 * (1 - nu * nu)), Ge = E / (4 * (2 - nu) * (1 + nu));
  const double c_kn = 4.0 / 3.0 * Ee, c_ks = 8 * Ge;
  const LawConstants law_k{c_kn, c_ks, gamma, mu, dt};
  // The floor: k_n = pi R^2 E* / R = pi R E* per ball (hilldem's linear ball-wall mapping), no shear.
  std::vector<double> floor_kn(n);
  for (std::size_t i = 0; i < n; ++i) floor_kn[i] = M_PI * kin[i].r * E;
  const double g = -9.81;
  long contacts_seen = 0;

  // The floor (linear, frictionless) and the law of motion of ball a (no local damping, as the bench).
  auto move = [&](std::size_t a) {
    Kin& k = kin[a];
    Spin& s = spin[a];
    const Acc& f = acc[a];
    const double pen = k.r - k.z;
    const double floor_f = pen > 0 ? floor_kn[a] * pen : 0.0;
    k.vx += f.fx * k.inv_m * dt;
    k.vy += f.fy * k.inv_m * dt;
    k.vz += ((f.fz + floor_f) * k.inv_m + g) * dt;
    s.wx += f.tx * inv_i[a] * dt, s.wy += f.ty * inv_i[a] * dt, s.wz += f.tz * inv_i[a] * dt;
    k.x += k.vx * dt, k.y += k.vy * dt, k.z += k.vz * dt;
  };
  auto step = [&](bool count) {
    for (std::size_t a = 0; a < n; ++a) acc[a] = Acc{0, 0, 0, 0, 0, 0};
    long touching = 0;
    for (std::size_t a = 0; a < n; ++a) {
      const Kin ka = kin[a];
      const Spin sa = spin[a];
      Acc fa{0, 0, 0, 0, 0, 0};
      for (std::uint32_t p = start[a]; p < start[a + 1]; ++p) {
        const std::uint32_t b = nb[p];
        const Kin& kb = kin[b];
        const double dx = kb.x + shift_x[image[p]] - ka.x, dy = kb.y + shift_y[image[p]] - ka.y, dz = kb.z - ka.z;
        const double d2 = dx * dx + dy * dy + dz * dz, rsum = ka.r + kb.r;
        History& h = hist[p];
        if (d2 >= rsum * rsum) {
          h.hx = h.hy = h.hz = 0;
          continue;
        }
        ++touching;
        const Spin& sb = spin[b];
        const PairOut o = pair_law(PairIn{dx, dy, dz, ka.r, kb.r, ka.vx, ka.vy, ka.vz, kb.vx, kb.vy, kb.vz, sa.wx, sa.wy,
                                          sa.wz, sb.wx, sb.wy, sb.wz, sa.inv_r, sb.inv_r, ka.inv_m, kb.inv_m, h.nx, h.ny,
                                          h.nz, h.hx, h.hy, h.hz},
                                   law_k);
        h = History{o.nx, o.ny, o.nz, o.hx, o.hy, o.hz};
        const double nx = o.nx, ny = o.ny, nz = o.nz, arm1 = o.arm1, arm2 = o.arm2;
        const double Fx = o.fx, Fy = o.fy, Fz = o.fz;  // on b
        const double cx = ny * Fz - nz * Fy, cy = nz * Fx - nx * Fz, cz = nx * Fy - ny * Fx;  // n × F
        fa.fx -= Fx, fa.fy -= Fy, fa.fz -= Fz;
        fa.tx -= arm1 * cx, fa.ty -= arm1 * cy, fa.tz -= arm1 * cz;
        Acc& fb = acc[b];
        fb.fx += Fx, fb.fy += Fy, fb.fz += Fz;
        fb.tx -= arm2 * cx, fb.ty -= arm2 * cy, fb.tz -= arm2 * cz;
      }
      Acc& ta = acc[a];
      ta.fx += fa.fx, ta.fy += fa.fy, ta.fz += fa.fz, ta.tx += fa.tx, ta.ty += fa.ty, ta.tz += fa.tz;
    }
    for (std::size_t a = 0; a < n; ++a) move(a);
    if (count) contacts_seen = touching;
  };
  // The same physics with the law over lanes of 64 touching pairs (gather, vectorised law, scatter),
  // as hilldem's ContactBatch, but lean: 27 gathered fields, forces accumulated directly.
  const int flags = argc > 4 ? std::atoi(argv[4]) : 1;  // the mode (see the head of the file)
  if (flags < 0 || flags > 63 || (flags > 1 && !(flags & 1))) {
    std::fprintf(stderr, "mode must be 0 (row by row) or 1 plus any of 2, 4, 8, 16, 32\n");
    return 2;
  }
  const bool late_mode = flags & 2, report = flags & 4, rowmeta = flags & 8, copy = flags & 16;
  const bool nobranch = flags & 32;
  struct Key { std::uint32_t a; std::uint8_t kind; std::uint32_t b; };
  struct Params { double mu, damp, suction; };
  std::vector<Key> keys(rowmeta ? pairs : 0);
  std::vector<std::uint8_t> exists(rowmeta ? pairs : 0, 1), model(rowmeta ? pairs : 0, 1);
  std::vector<Params> params(rowmeta ? pairs : 0, Params{mu, gamma, 0.0});
  for (std::size_t a = 0; a < n && rowmeta; ++a)
    for (std::uint32_t p = start[a]; p < start[a + 1]; ++p) keys[p] = Key{static_cast<std::uint32_t>(a), 0, nb[p]};
  std::vector<double> r_gap(report ? pairs : 0), r_fn(report ? pairs : 0), r_fm(report ? pairs : 0), r_trial(report ? pairs : 0);
  std::vector<std::uint8_t> r_active(report ? pairs : 0), r_moist(report ? pairs : 0);
  struct V3 { double x, y, z; };
  std::vector<V3> r_force(report ? pairs : 0);
  std::vector<V3> col_pos(copy ? n : 0), col_vel(copy ? n : 0), col_spin(copy ? n : 0);
  for (std::size_t i = 0; i < n && copy; ++i)
    col_pos[i] = {kin[i].x, kin[i].y, kin[i].z}, col_vel[i] = {kin[i].vx, kin[i].vy, kin[i].vz}, col_spin[i] = {spin[i].wx, spin[i].wy, spin[i].wz};
  std::vector<Acc> row_out(late_mode ? pairs : 0);
  std::vector<std::uint32_t> late_start(n + 1, 0), late;
  if (late_mode) {
    for (std::size_t p = 0; p < pairs; ++p) ++late_start[nb[p] + 1];
    for (std::size_t i = 0; i < n; ++i) late_start[i + 1] += late_start[i];
    late.resize(pairs);
    std::vector<std::uint32_t> fill(late_start.begin(), late_start.end() - 1);
    for (std::size_t p = 0; p < pairs; ++p) late[fill[nb[p]]++] = static_cast<std::uint32_t>(p);
  }
  constexpr int L = 64;
  enum { DX, DY, DZ, RA, RB, VAX, VAY, VAZ, VBX, VBY, VBZ, WAX, WAY, WAZ, WBX, WBY, WBZ, IRA, IRB, IMA, IMB,
         NOX, NOY, NOZ, HX, HY, HZ, NF,
         // outputs
         ONX = NF, ONY, ONZ, OHX, OHY, OHZ, OFX, OFY, OFZ, OA1, OA2, NALL };
  alignas(64) static double lane[NALL][L];
  std::uint32_t lane_p[L], lane_a[L], lane_b[L];
  auto law = [&](int cnt) {
    const int m = (cnt + 7) / 8 * 8;
    for (int f = 0; f < NF; ++f)
      for (int i = cnt; i < m; ++i) lane[f][i] = lane[f][cnt - 1];
#pragma omp simd
    for (int i = 0; i < m; ++i) {
      const PairOut o = pair_law(
          PairIn{lane[DX][i],  lane[DY][i],  lane[DZ][i],  lane[RA][i],  lane[RB][i],  lane[VAX][i], lane[VAY][i],
                 lane[VAZ][i], lane[VBX][i], lane[VBY][i], lane[VBZ][i], lane[WAX][i], lane[WAY][i], lane[WAZ][i],
                 lane[WBX][i], lane[WBY][i], lane[WBZ][i], lane[IRA][i], lane[IRB][i], lane[IMA][i], lane[IMB][i],
                 lane[NOX][i], lane[NOY][i], lane[NOZ][i], lane[HX][i],  lane[HY][i],  lane[HZ][i]},
          law_k);
      lane[ONX][i] = o.nx, lane[ONY][i] = o.ny, lane[ONZ][i] = o.nz;
      lane[OHX][i] = o.hx, lane[OHY][i] = o.hy, lane[OHZ][i] = o.hz;
      lane[OFX][i] = o.fx, lane[OFY][i] = o.fy, lane[OFZ][i] = o.fz;
      lane[OA1][i] = o.arm1, lane[OA2][i] = o.arm2;
    }
    for (int i = 0; i < cnt; ++i) {
      const double nx = lane[ONX][i], ny = lane[ONY][i], nz = lane[ONZ][i];
      const double Fx = lane[OFX][i], Fy = lane[OFY][i], Fz = lane[OFZ][i];
      hist[lane_p[i]] = History{nx, ny, nz, lane[OHX][i], lane[OHY][i], lane[OHZ][i]};
      const double cx = ny * Fz - nz * Fy, cy = nz * Fx - nx * Fz, cz = nx * Fy - ny * Fx;
      const double a1 = lane[OA1][i], a2 = lane[OA2][i];
      Acc& fa = acc[lane_a[i]];
      fa.fx -= Fx, fa.fy -= Fy, fa.fz -= Fz;
      fa.tx -= a1 * cx, fa.ty -= a1 * cy, fa.tz -= a1 * cz;
      if (report) {
        const std::uint32_t p = lane_p[i];
        r_gap[p] = lane[OA1][i] - lane[OA2][i];  // (stand-in values: the bytes are what counts)
        r_fn[p] = Fx, r_fm[p] = 0.0, r_trial[p] = Fy, r_force[p] = {Fx, Fy, Fz};
        r_active[p] = 1, r_moist[p] = 0;
      }
      if (late_mode) {  // hilldem's way: the row's force and its moment on b in per-row columns
        row_out[lane_p[i]] = Acc{Fx, Fy, Fz, -a2 * cx, -a2 * cy, -a2 * cz};
        continue;
      }
      Acc& fb = acc[lane_b[i]];
      fb.fx += Fx, fb.fy += Fy, fb.fz += Fz;
      fb.tx -= a2 * cx, fb.ty -= a2 * cy, fb.tz -= a2 * cz;
    }
  };
  auto step_batched = [&](bool count) {
    for (std::size_t a = 0; a < n; ++a) acc[a] = Acc{0, 0, 0, 0, 0, 0};
    if (copy)
      for (std::size_t a = 0; a < n; ++a) {
        kin[a].x = col_pos[a].x, kin[a].y = col_pos[a].y, kin[a].z = col_pos[a].z;
        kin[a].vx = col_vel[a].x, kin[a].vy = col_vel[a].y, kin[a].vz = col_vel[a].z;
        spin[a].wx = col_spin[a].x, spin[a].wy = col_spin[a].y, spin[a].wz = col_spin[a].z;
      }
    long touching = 0;
    int cnt = 0;
    // Lane i's 27 fields from the row, its two balls and its history.
    auto put_lane = [&](int i, std::uint32_t p, std::size_t a, std::uint32_t b, double dx, double dy, double dz,
                        const Kin& ka, const Kin& kb, const Spin& sa, const Spin& sb,
                        const History& h) __attribute__((always_inline)) {
      lane_p[i] = p, lane_a[i] = static_cast<std::uint32_t>(a), lane_b[i] = b;
      lane[DX][i] = dx, lane[DY][i] = dy, lane[DZ][i] = dz;
      lane[RA][i] = ka.r, lane[RB][i] = kb.r;
      lane[VAX][i] = ka.vx, lane[VAY][i] = ka.vy, lane[VAZ][i] = ka.vz;
      lane[VBX][i] = kb.vx, lane[VBY][i] = kb.vy, lane[VBZ][i] = kb.vz;
      lane[WAX][i] = sa.wx, lane[WAY][i] = sa.wy, lane[WAZ][i] = sa.wz;
      lane[WBX][i] = sb.wx, lane[WBY][i] = sb.wy, lane[WBZ][i] = sb.wz;
      lane[IRA][i] = sa.inv_r, lane[IRB][i] = sb.inv_r, lane[IMA][i] = ka.inv_m, lane[IMB][i] = kb.inv_m;
      lane[NOX][i] = h.nx, lane[NOY][i] = h.ny, lane[NOZ][i] = h.nz;
      lane[HX][i] = h.hx, lane[HY][i] = h.hy, lane[HZ][i] = h.hz;
      if (rowmeta) lane[IRA][i] += 0.0 * (params[p].mu + params[p].damp + params[p].suction + model[p]);
    };
    for (std::size_t a = 0; a < n; ++a) {
      const Kin& ka = kin[a];
      const Spin& sa = spin[a];
      for (std::uint32_t p = start[a]; p < start[a + 1]; ++p) {
        const std::uint32_t b = rowmeta ? keys[p].b : nb[p];
        if (p + 16 < pairs) {  // the records of the neighbour 16 rows on (as hilldem's pair loop)
          __builtin_prefetch(&kin[nb[p + 16]]);
          __builtin_prefetch(&spin[nb[p + 16]]);
          __builtin_prefetch(&acc[nb[p + 16]]);
        }
        const Kin& kb = kin[b];
        const double dx = kb.x + shift_x[image[p]] - ka.x, dy = kb.y + shift_y[image[p]] - ka.y, dz = kb.z - ka.z;
        const double d2 = dx * dx + dy * dy + dz * dz, rsum = ka.r + kb.r;
        History& h = hist[p];
        if (nobranch) {
          // The row's fields into the next lane's slot whether or not the pair touches; only a pair
          // apart with something to clear branches (rare, and the same way every step).
          unsigned touch = static_cast<unsigned>(d2 < rsum * rsum) & static_cast<unsigned>(!rowmeta || exists[p]);
          asm("" : "+r"(touch));  // computed whole: GCC would otherwise branch on the distance first
          unsigned clear = static_cast<unsigned>(!touch) &
                           static_cast<unsigned>((h.hx != 0.0) | (h.hy != 0.0) | (h.hz != 0.0) |
                                                 (late_mode && row_out[p].fx != 0.0));
          asm("" : "+r"(clear));  // one branch on the whole condition, not a first one on `touch`
          if (clear != 0) {
            h.hx = h.hy = h.hz = 0;
            if (late_mode) row_out[p] = Acc{0, 0, 0, 0, 0, 0};
          }
          const Spin& sb = spin[b];
          const int i = cnt;
          put_lane(i, p, a, b, dx, dy, dz, ka, kb, sa, sb, h);
          cnt += static_cast<int>(touch);
          touching += touch;
          if (cnt == L) law(cnt), cnt = 0;
          continue;
        }
        if (d2 >= rsum * rsum || (rowmeta && !exists[p])) {
          // A pair apart forgets its shear force, and gives no force: written only when there is
          // something to clear (as hilldem, whose rows that are not contacts are not written).
          if (h.hx != 0.0 || h.hy != 0.0 || h.hz != 0.0) h.hx = h.hy = h.hz = 0;
          if (late_mode && row_out[p].fx != 0.0) row_out[p] = Acc{0, 0, 0, 0, 0, 0};
          continue;
        }
        ++touching;
        const Spin& sb = spin[b];
        const int i = cnt++;
        put_lane(i, p, a, b, dx, dy, dz, ka, kb, sa, sb, h);
        if (cnt == L) law(cnt), cnt = 0;
      }
    }
    if (cnt > 0) law(cnt);
    if (late_mode)
      for (std::size_t a = 0; a < n; ++a) {
        Acc f = acc[a];
        for (std::uint32_t k = late_start[a]; k < late_start[a + 1]; ++k) {
          const Acc& r = row_out[late[k]];
          f.fx += r.fx, f.fy += r.fy, f.fz += r.fz, f.tx += r.tx, f.ty += r.ty, f.tz += r.tz;
        }
        acc[a] = f;
      }
    for (std::size_t a = 0; a < n; ++a) {
      move(a);
      if (copy) {
        const Kin& k = kin[a];
        const Spin& s = spin[a];
        col_pos[a] = {k.x, k.y, k.z}, col_vel[a] = {k.vx, k.vy, k.vz}, col_spin[a] = {s.wx, s.wy, s.wz};
      }
    }
    if (count) contacts_seen = touching;
  };
  // Warm-up (a fifth of the steps), then the timed steps; the contacts are counted on the last one.
  auto run = [&](auto& one_step) {
    for (long k = 0; k < steps / 5; ++k) one_step(false);
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 0; k < steps; ++k) one_step(k == steps - 1);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("mode=%d particles=%zu steps=%ld wall_s=%.3f particle_steps_per_s=%.4g contacts_per_particle=%.3f "
                "pairs_per_particle=%.3f\n",
                flags, n, steps, wall, n * steps / wall, 2.0 * contacts_seen / n, static_cast<double>(pairs) / n);
  };
  if (flags & 1) run(step_batched);
  else run(step);
  return 0;
}
