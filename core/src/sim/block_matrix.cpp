#include "strata/core/sim/block_matrix.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {

bool BlockSymmetricMatrix::assign(const SparseMatrixd& A) {
  // The arrays keep their size from the last copy: a matrix of the same pattern (the next Newton
  // system) overwrites them without a fill.
  m_num_blocks = 0;
  const Index n = A.cols();
  if (!A.isCompressed() || A.rows() != n || n % 3 != 0) {
    clear();
    return false;
  }
  const Index num_blocks = n / 3;
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* values = A.valuePtr();
  // Three columns of one length, a multiple of 3.
  m_outer.resize(num_blocks + 1);
  m_outer[0] = 0;
  for (Index b = 0; b < num_blocks; ++b) {
    const int length = outer[3 * b + 1] - outer[3 * b];
    if (length % 3 != 0 || outer[3 * b + 2] - outer[3 * b + 1] != length ||
        outer[3 * b + 3] - outer[3 * b + 2] != length) {
      clear();
      return false;
    }
    m_outer[b + 1] = m_outer[b] + length / 3;
  }
  m_block_rows.resize(m_outer[num_blocks]);
  m_values.resize(9 * static_cast<std::size_t>(m_outer[num_blocks]));
  m_single.resize(m_keep_single ? m_values.size() : 0);
  float* single = m_keep_single ? m_single.data() : nullptr;
  // The rows of each column in triples, the same in the three columns; copied as checked.
  const bool blocked = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, num_blocks, 512), true,
      [&](const tbb::blocked_range<Index>& range, bool ok) {
        for (Index b = range.begin(); ok && b != range.end(); ++b) {
          const int start = outer[3 * b];
          const int length = outer[3 * b + 1] - start;
          const int* rows0 = inner + start;
          const int* rows1 = rows0 + length;
          const int* rows2 = rows1 + length;
          for (int k = 0; ok && k < length; k += 3) {
            const int r = rows0[k];
            ok = r % 3 == 0 && rows0[k + 1] == r + 1 && rows0[k + 2] == r + 2;
            for (int i = 0; ok && i < 3; ++i)
              ok = rows1[k + i] == r + i && rows2[k + i] == r + i;
            const int block = m_outer[b] + k / 3;
            m_block_rows[block] = r / 3;
            double* entries = &m_values[9 * static_cast<std::size_t>(block)];
            for (int j = 0; j < 3; ++j)
              for (int i = 0; i < 3; ++i)
                entries[3 * j + i] = values[start + j * length + k + i];
            if (single != nullptr)
              for (int e = 0; e < 9; ++e)
                single[9 * static_cast<std::size_t>(block) + e] = static_cast<float>(entries[e]);
          }
        }
        return ok;
      },
      std::logical_and<bool>());
  if (!blocked) {
    clear();
    return false;
  }
  m_num_blocks = num_blocks;
  return true;
}

void BlockSymmetricMatrix::clear() {
  m_num_blocks = 0;
  m_outer.clear();
  m_block_rows.clear();
  m_values.clear();
  m_single.clear();
}

void BlockSymmetricMatrix::multiply(ConstRef<VectorXd> x, VectorXd& y) const {
  multiply(x, y, {});
}

double BlockSymmetricMatrix::multiply(ConstRef<VectorXd> x, VectorXd& y,
                                      const std::function<double(Index, Index)>& after) const {
  return product(m_values.data(), x, y, after);
}

double BlockSymmetricMatrix::multiply_single(
    ConstRef<VectorXd> x, VectorXd& y, const std::function<double(Index, Index)>& after) const {
  STRATA_VERIFY(has_single_precision(),
                "BlockSymmetricMatrix::multiply_single: no single-precision values kept");
  return product(m_single.data(), x, y, after);
}

template <typename Scalar>
double BlockSymmetricMatrix::product(const Scalar* values, ConstRef<VectorXd> x, VectorXd& y,
                                     const std::function<double(Index, Index)>& after) const {
  STRATA_VERIFY(x.size() == rows(), "BlockSymmetricMatrix::multiply: x has the wrong size");
  y.resize(rows());
  const double* xs = x.data();
  double* ys = y.data();
  const int* outer = m_outer.data();
  const int* block_rows = m_block_rows.data();
  const Index num_chunks = (m_num_blocks + kBlockChunk - 1) / kBlockChunk;
  std::vector<double> partial(static_cast<std::size_t>(after ? num_chunks : 0));
  // Row 3b + j of the (symmetric) matrix is column 3b + j: entry (i, j) of each block of block
  // column b times x at its block row.
  tbb::parallel_for(Index(0), num_chunks, [&](Index chunk) {
    const Index first = chunk * kBlockChunk;
    const Index last = std::min(m_num_blocks, first + kBlockChunk);
    for (Index b = first; b != last; ++b) {
      double y0 = 0.0, y1 = 0.0, y2 = 0.0;
      for (int k = outer[b]; k < outer[b + 1]; ++k) {
        const double* xa = xs + 3 * static_cast<Index>(block_rows[k]);
        const Scalar* entries = values + 9 * static_cast<std::size_t>(k);
        y0 += entries[0] * xa[0] + entries[1] * xa[1] + entries[2] * xa[2];
        y1 += entries[3] * xa[0] + entries[4] * xa[1] + entries[5] * xa[2];
        y2 += entries[6] * xa[0] + entries[7] * xa[1] + entries[8] * xa[2];
      }
      ys[3 * b] = y0;
      ys[3 * b + 1] = y1;
      ys[3 * b + 2] = y2;
    }
    if (after) partial[chunk] = after(3 * first, 3 * last);
  });
  double sum = 0.0;
  for (const double value : partial)
    sum += value;
  return sum;
}

}  // namespace strata
