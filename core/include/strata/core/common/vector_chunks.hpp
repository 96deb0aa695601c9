#pragma once
/// \file vector_chunks.hpp
/// Vector kernels of the iterative solvers in parallel over fixed chunks of entries. The chunks
/// do not depend on the thread count, and sums add the chunks' partial sums in chunk order, so
/// every result is the same at any thread count.
#include <functional>

#include "strata/core/common/types.hpp"

namespace strata {

/// Entries per chunk.
inline constexpr Index kVectorChunk = 2048;

/// f(begin, end) on each chunk [k·kVectorChunk, min((k + 1)·kVectorChunk, n)) of [0, n), in
/// parallel (inline for a single chunk).
void for_each_vector_chunk(Index n, const std::function<void(Index, Index)>& f);

/// Σ_k f(begin_k, end_k) over the same chunks, evaluated in parallel and added in chunk order.
double sum_over_vector_chunks(Index n, const std::function<double(Index, Index)>& f);

/// a · b by chunks (the sizes must agree).
double chunked_dot(ConstRef<VectorXd> a, ConstRef<VectorXd> b);

}  // namespace strata
