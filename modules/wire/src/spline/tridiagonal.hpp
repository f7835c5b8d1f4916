// Internal: the tangent systems' tridiagonal solvers: one system (twisted elimination), a cyclic one
// (Sherman-Morrison), and two or four systems of one size side by side (bit for bit the one-system solve's).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>

namespace wire::curve_stage {

// Tridiagonal solve (sub a, diagonal b, super c) of n rows for C right-hand sides r[0..C) (structure of arrays;
// each component gets exactly the operations the vector form gave it); callers pass diagonally dominant rows.
// Twisted ("burn at both ends") elimination: rows are eliminated from the top and from the bottom at once, meeting
// in the middle row, so the two serial chains of one division each per row run side by side (half the latency of
// Thomas' one chain). The chains' values are carried in registers (a store through r may not alias f or the
// other components, so nothing is reloaded on the critical path).
template <int C>
void thomas_kernel(const double* __restrict a, const double* __restrict b, const double* __restrict c, std::size_t n,
                   double* __restrict f, double* __restrict rx, double* __restrict ry, double* __restrict rz) {
    // One row step for every component: r[i] = (r[i] - m * prev) * inv, prev = r[i].
    const auto step = [&](std::size_t i, double m, double inv, double& px, double& py, double& pz) {
        px = (rx[i] - m * px) * inv, rx[i] = px;
        if constexpr (C == 3) {
            py = (ry[i] - m * py) * inv, ry[i] = py;
            pz = (rz[i] - m * pz) * inv, rz[i] = pz;
        }
    };
    const auto first = [&](std::size_t i, double inv, double& px, double& py, double& pz) {  // r[i] * inv
        px = rx[i] * inv, rx[i] = px;
        if constexpr (C == 3) {
            py = ry[i] * inv, ry[i] = py;
            pz = rz[i] * inv, rz[i] = pz;
        }
    };
    const auto back = [&](std::size_t i, double& px, double& py, double& pz) {
        px = rx[i] - f[i] * px, rx[i] = px;
        if constexpr (C == 3) {
            py = ry[i] - f[i] * py, ry[i] = py;
            pz = rz[i] - f[i] * pz, rz[i] = pz;
        }
    };
    double tx = 0.0, ty = 0.0, tz = 0.0;  // the top chain's last row
    double inv = 1.0 / b[0];
    double ft = c[0] * inv;
    f[0] = ft;
    first(0, inv, tx, ty, tz);
    if (n < 4) {  // plain Thomas
        for (std::size_t i = 1; i < n; ++i) {
            inv = 1.0 / (b[i] - a[i] * ft);
            ft = c[i] * inv;
            f[i] = ft;
            step(i, a[i], inv, tx, ty, tz);
        }
        for (std::size_t i = n - 1; i-- > 0;) back(i, tx, ty, tz);
        return;
    }
    const std::size_t p = n / 2;  // the meeting row; top rows 0..p-1, bottom rows p+1..n-1
    double bx = 0.0, by = 0.0, bz = 0.0;  // the bottom chain's last row
    inv = 1.0 / b[n - 1];
    double fb = a[n - 1] * inv;
    f[n - 1] = fb;
    first(n - 1, inv, bx, by, bz);
    const auto top = [&](std::size_t i) {
        const double it = 1.0 / (b[i] - a[i] * ft);
        ft = c[i] * it;
        f[i] = ft;
        step(i, a[i], it, tx, ty, tz);
    };
    const auto bottom = [&](std::size_t j) {
        const double ib = 1.0 / (b[j] - c[j] * fb);
        fb = a[j] * ib;
        f[j] = fb;
        step(j, c[j], ib, bx, by, bz);
    };
    std::size_t i = 1, j = n - 2;
    for (; i < p && j > p; ++i, --j) top(i), bottom(j);
    for (; i < p; ++i) top(i);
    for (; j > p; --j) bottom(j);
    // Row p with x[p-1] = r[p-1] - f[p-1] x[p] and x[p+1] = r[p+1] - f[p+1] x[p] substituted.
    inv = 1.0 / (b[p] - a[p] * ft - c[p] * fb);
    tx = (rx[p] - a[p] * tx - c[p] * bx) * inv, rx[p] = tx, bx = tx;
    if constexpr (C == 3) {
        ty = (ry[p] - a[p] * ty - c[p] * by) * inv, ry[p] = ty, by = ty;
        tz = (rz[p] - a[p] * tz - c[p] * bz) * inv, rz[p] = tz, bz = tz;
    }
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        back(i, tx, ty, tz);
        back(j, bx, by, bz);
    }
    while (i > 0) --i, back(i, tx, ty, tz);
    while (j + 1 < n) ++j, back(j, bx, by, bz);
}

// Cyclic tridiagonal (corners a[0] at column n-1 and c[n-1] at column 0) by Sherman-Morrison, n >= 3.

void thomas_cyclic(const double* a, const double* b, const double* c, std::size_t n, double* const* r);

// An automatic (or c2) spline's tangent system between its setup and its solution, so that the tridiagonal
// solves of two wires can run side by side (thomas_pair): the solve is a serial chain of divisions per wire, and
// two independent chains take the time of one.
struct TangentSolve {
    double* D[3] = {};        // node tangents per unit chord (n + 1 each; index n repeats node 0's)
    double *a = nullptr, *b = nullptr, *c = nullptr, *f = nullptr;  // interior rows (of nodes 1 .. m); f: factors
    std::size_t n = 0, m = 0;  // nodes; interior rows
    bool pending = false;      // the interior rows still to solve (an open wire of >= 4 nodes), then the ends
    glm::dvec3 r0{}, rl{};          // the end rows' right-hand sides and diagonals (beta D0 + D1 = r0, ...)
    double beta0 = 0.0, betal = 0.0;
    double* r(int q) const { return D[q] + 1; }  // right-hand sides of the interior rows, solved in place
};

// Solves a pending system alone.
inline void solve(TangentSolve& ts) {
    thomas_kernel<3>(ts.a, ts.b, ts.c, ts.m, ts.f, ts.r(0), ts.r(1), ts.r(2));
}

// thomas_kernel<3> for two systems of the same size (>= 4 rows) at once: system s in lane s of two-double
// vectors (native on every x86-64), so every row gets exactly the operations thomas_kernel gives it (each lane
// is rounded as the scalar operation; the results are bit for bit its) and the two systems' division chains
// run side by side, in the registers (scalar code for two systems spilled its chain values).
void thomas_pair(TangentSolve& s0, TangentSolve& s1);

// Four systems of the same size (>= 4 rows) at once: system s in lane s of four-double vectors, the rows of the
// four interleaved first (row i of system s at 4i + s) so that a row of all four is one load or store (two-double
// lanes read from separate arrays, as thomas_pair's, cost two instructions a load and three a store: that loop is
// bound by them, not by its division chain). Each lane gets exactly thomas_kernel's operations (the same twisted
// elimination, the same meeting row), so the results are bit for bit its. 4 lanes: ymm on AVX2 and AVX-512
// machines, two xmm halves on the SSE2 baseline.
// Solves four pending systems of the same size (>= 4 rows) side by side.
void thomas_quad(TangentSolve* const s[4]);

}  // namespace wire::curve_stage
