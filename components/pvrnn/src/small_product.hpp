// Internal: C = A * B for the per-step products of the passes: A is a weight matrix (tens of
// rows and columns, column-major, in L1), B a block of a few columns (one per sequence).
//
// Why not Eigen's product: at these shapes its GEMM repacks A on every call (thousands of calls
// per epoch) and its lazy product runs one FMA chain per coefficient. This kernel keeps a
// 2-packet x 4-column tile of C in registers and streams A's columns once per 4 columns of B.
// Rows that do not fill a packet are computed by a last packet that overlaps the previous one
// (the same sums in the same order: equal bits), or coefficient by coefficient when A has fewer
// rows than a packet.
//
// Contract: C must not alias A or B; all three dense column-major (inner stride 1). Every
// coefficient of C is the sum over k in increasing order of A(i,k) * B(k,j), whatever the
// number of columns of B, so a sequence's result does not depend on its neighbours.
#pragma once

#include <Eigen/Core>

// Eigen's packet types (__m512 ...) lose their alignment attributes as template arguments;
// harmless here (unaligned loads and stores only). Eigen silences the same in its own headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"

namespace dyad::pvrnn::internal {

template <typename Scalar>
constexpr int kPacket = Eigen::internal::packet_traits<Scalar>::size;

template <typename Scalar, int Rows, int Cols, bool Add>
inline void ProductTile(const Scalar* a, Eigen::Index lda, Eigen::Index k, const Scalar* b, Eigen::Index ldb,
                        Scalar* c, Eigen::Index ldc) {
  using namespace Eigen::internal;
  using Packet = typename packet_traits<Scalar>::type;
  constexpr int P = kPacket<Scalar>;
  Packet acc[Rows][Cols];
  for (int r = 0; r < Rows; ++r)
    for (int j = 0; j < Cols; ++j) acc[r][j] = Add ? ploadu<Packet>(c + j * ldc + r * P) : pset1<Packet>(Scalar(0));
  for (Eigen::Index p = 0; p < k; ++p) {
    Packet col[Rows];
    for (int r = 0; r < Rows; ++r) col[r] = ploadu<Packet>(a + p * lda + r * P);
    for (int j = 0; j < Cols; ++j) {
      const Packet bj = pset1<Packet>(b[j * ldb + p]);
      for (int r = 0; r < Rows; ++r) acc[r][j] = pmadd(col[r], bj, acc[r][j]);
    }
  }
  for (int r = 0; r < Rows; ++r)
    for (int j = 0; j < Cols; ++j) pstoreu(c + j * ldc + r * P, acc[r][j]);
}

// `Cols` columns of C, every row. Add: C += A * B (no overlapping tile then).
template <typename Scalar, int Cols, bool Add>
inline void ProductColumns(const Scalar* a, Eigen::Index lda, Eigen::Index m, Eigen::Index k, const Scalar* b,
                           Eigen::Index ldb, Scalar* c, Eigen::Index ldc) {
  constexpr int P = kPacket<Scalar>;
  Eigen::Index i = 0;
  for (; i + 2 * P <= m; i += 2 * P) ProductTile<Scalar, 2, Cols, Add>(a + i, lda, k, b, ldb, c + i, ldc);
  if (!Add && m >= 2 * P && m - i > P) {
    // One packet is latency-bound (Cols FMA chains): more than a packet's worth of rows goes
    // into an overlapping two-packet tile.
    ProductTile<Scalar, 2, Cols, Add>(a + m - 2 * P, lda, k, b, ldb, c + m - 2 * P, ldc);
    return;
  }
  for (; i + P <= m; i += P) ProductTile<Scalar, 1, Cols, Add>(a + i, lda, k, b, ldb, c + i, ldc);
  if (!Add && i < m && m >= P) {
    ProductTile<Scalar, 1, Cols, Add>(a + m - P, lda, k, b, ldb, c + m - P, ldc);
    return;
  }
  for (; i < m; ++i)  // fewer rows than a packet
    for (int j = 0; j < Cols; ++j) {
      Scalar s = Add ? c[j * ldc + i] : Scalar(0);
      for (Eigen::Index p = 0; p < k; ++p) s += a[p * lda + i] * b[j * ldb + p];
      c[j * ldc + i] = s;
    }
}

// c = a * b, or c += a * b with Add.
template <typename Scalar, bool Add = false, typename A, typename B, typename C>
inline void SmallProduct(const A& a, const B& b, C&& c) {
  const Eigen::Index m = a.rows(), k = a.cols(), n = b.cols();
  const Scalar* pa = a.data();
  const Scalar* pb = b.data();
  Scalar* pc = c.data();
  const Eigen::Index lda = a.outerStride(), ldb = b.outerStride(), ldc = c.outerStride();
  Eigen::Index j = 0;
  for (; j + 4 <= n; j += 4) ProductColumns<Scalar, 4, Add>(pa, lda, m, k, pb + j * ldb, ldb, pc + j * ldc, ldc);
  switch (n - j) {
    case 3: ProductColumns<Scalar, 3, Add>(pa, lda, m, k, pb + j * ldb, ldb, pc + j * ldc, ldc); break;
    case 2: ProductColumns<Scalar, 2, Add>(pa, lda, m, k, pb + j * ldb, ldb, pc + j * ldc, ldc); break;
    case 1: ProductColumns<Scalar, 1, Add>(pa, lda, m, k, pb + j * ldb, ldb, pc + j * ldc, ldc); break;
    default: break;
  }
}

}  // namespace dyad::pvrnn::internal

#pragma GCC diagnostic pop
