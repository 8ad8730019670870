// MeshSink's block call by default: the block's vertices, triangles and done vertices one at a
// time, in the order the calls would have come (include/g2s/mesh_sink.hpp).
#include "g2s/mesh_sink.hpp"

namespace g2s {

void MeshSink::block(const SinkBlock& b, std::uint32_t first_vertex, std::uint32_t first_group,
                     std::unique_ptr<SinkBlockWork> work) {
  (void)work;
  std::uint32_t next_new = 0;
  std::size_t next_done = 0;
  for (std::size_t k = 0; k < b.triangles.size(); ++k) {
    const Triangle& t = b.triangles[k];
    for (Index v : t) {
      if (v == next_new) {
        vertex(b.ids[v], &b.xyz[3 * std::size_t{v}]);
        ++next_new;
      }
    }
    triangle({first_vertex + t[0], first_vertex + t[1], first_vertex + t[2]},
             {&b.xyz[3 * std::size_t{t[0]}], &b.xyz[3 * std::size_t{t[1]}],
              &b.xyz[3 * std::size_t{t[2]}]},
             first_group + b.group[k]);
    for (; next_done < b.done.size() && b.done[next_done].first == k; ++next_done) {
      vertex_done(first_vertex + b.done[next_done].second);
    }
  }
}

}  // namespace g2s
