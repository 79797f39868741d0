// The passes of a reconstruction in blocks (vitri/blocks.hpp, docs/blocks.md) as functions of the module,
// for vitri.blocks (python/vitri/blocks.py): each pass a pure function of what it is given, its results
// picklable (the library's binary encodings), so that a distributed engine (Dask) can run the blocks as
// tasks on other processes and machines. Sizes are absolute here (the data's units): the precision, the
// merge halo.
#include "common.hpp"

#include "vitri/blocks.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vitri::python {
namespace {

py::bytes to_bytes(const std::vector<std::uint8_t>& v) {
  return py::bytes(reinterpret_cast<const char*>(v.data()), v.size());
}

template <class T, class Decode>
T from_bytes(const py::bytes& b, Decode decode) {
  char* data = nullptr;
  py::ssize_t size = 0;
  if (PYBIND11_BYTES_AS_STRING_AND_SIZE(b.ptr(), &data, &size) != 0) throw py::error_already_set();
  return decode(reinterpret_cast<const std::uint8_t*>(data), static_cast<std::size_t>(size));
}

std::array<int, 3> counts_arg(py::handle v) {
  std::array<int, 3> c{};
  if (py::isinstance<py::int_>(v)) {
    const int n = v.cast<int>();
    c = {n, n, n};
  } else {
    const auto seq = v.cast<std::vector<int>>();
    if (seq.size() != 3) throw InvalidArgument("counts: an integer or three integers, got " + std::to_string(seq.size()));
    c = {seq[0], seq[1], seq[2]};
  }
  return c;
}

std::vector<const BlockSeeds*> seeds_list(py::handle list, const char* name) {
  std::vector<const BlockSeeds*> out;
  for (py::handle h : list) {
    if (h.is_none()) {
      out.push_back(nullptr);
      continue;
    }
    if (!py::isinstance<BlockSeeds>(h))
      throw py::type_error(std::string(name) + ": expected BlockSeeds or None, got " +
                           std::string(py::str(py::type::of(h))));
    out.push_back(h.cast<const BlockSeeds*>());
  }
  return out;
}

py::array ids_array(const BlockSeeds& s) {
  std::vector<std::uint64_t> ids(s.points.size());
  for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = s.id(k);
  return py::array_t<std::uint64_t>(static_cast<py::ssize_t>(ids.size()), ids.data());
}

}  // namespace

void bind_blocks(py::module_& m) {
  py::class_<BlockPlan>(m, "BlockPlan",
                        "The split of a reconstruction in blocks: the grid over the points' box grown by the data "
                        "halo, the data's spacing (plan_blocks()). Picklable.")
      .def_property_readonly("counts", [](const BlockPlan& p) { return p.grid.counts(); })
      .def_property_readonly("size", [](const BlockPlan& p) { return p.grid.size(); }, "number of blocks")
      .def_property_readonly("spacing", [](const BlockPlan& p) { return p.spacing; })
      .def_property_readonly("data_halo", [](const BlockPlan& p) { return p.data_halo; })
      .def_property_readonly("domain",
                             [](const BlockPlan& p) {
                               const Box3& d = p.grid.domain();
                               return py::make_tuple(py::make_tuple(d.lo.x, d.lo.y, d.lo.z),
                                                     py::make_tuple(d.hi.x, d.hi.y, d.hi.z));
                             })
      .def("cell",
           [](const BlockPlan& p, int b) {
             if (b < 0 || b >= p.grid.size())
               throw InvalidArgument("cell: block " + std::to_string(b) + " of " + std::to_string(p.grid.size()));
             const Box3 c = p.grid.cell(b);
             return py::make_tuple(py::make_tuple(c.lo.x, c.lo.y, c.lo.z), py::make_tuple(c.hi.x, c.hi.y, c.hi.z));
           },
           py::arg("block"))
      .def("block_points",
           [](const BlockPlan& p, int b, py::handle points) {
             if (b < 0 || b >= p.grid.size())
               throw InvalidArgument("block_points: block " + std::to_string(b) + " of " +
                                     std::to_string(p.grid.size()));
             const std::vector<Point3> pts = points_arg(points, "points");
             std::vector<std::size_t> idx;
             {
               py::gil_scoped_release release;
               idx = block_points(p, b, pts);
             }
             std::vector<std::uint64_t> out(idx.begin(), idx.end());
             return py::array_t<std::uint64_t>(static_cast<py::ssize_t>(out.size()), out.data());
           },
           py::arg("block"), py::arg("points"),
           "Indices (uint64, increasing) of the points block `block` sees: those within the data halo of its cell.")
      .def("cells_near",
           [](const BlockPlan& p, int b, double halo) {
             // The blocks whose owned vertices can lie within `halo` of cell b (cells grown by it overlap).
             std::vector<int> out;
             const Box3 x = p.grid.cell(b);
             for (int c = 0; c < p.grid.size(); ++c) {
               const Box3 y = p.grid.cell(c);
               const bool apart = x.lo.x > y.hi.x + 2 * halo || y.lo.x > x.hi.x + 2 * halo || x.lo.y > y.hi.y + 2 * halo ||
                                  y.lo.y > x.hi.y + 2 * halo || x.lo.z > y.hi.z + 2 * halo || y.lo.z > x.hi.z + 2 * halo;
               if (!apart) out.push_back(c);
             }
             return out;
           },
           py::arg("block"), py::arg("halo"))
      .def(py::pickle([](const BlockPlan& p) { return to_bytes(encode_block_plan(p)); },
                      [](const py::bytes& b) { return from_bytes<BlockPlan>(b, decode_block_plan); }))
      .def("__repr__", [](const BlockPlan& p) {
        const auto c = p.grid.counts();
        return "<vitri.BlockPlan " + std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" + std::to_string(c[2]) +
               ", spacing " + std::to_string(p.spacing) + ">";
      });

  py::class_<BlockSeeds>(m, "BlockSeeds",
                         "Pass 1's result for one block (refine_block()): the Delaunay vertices it owns with f and "
                         "grad f there, its prepared points. Picklable.")
      .def_property_readonly("block", [](const BlockSeeds& s) { return s.block; })
      .def_property_readonly("points", [](const BlockSeeds& s) { return points_out(std::vector<Point3>(s.points)); })
      .def_property_readonly("values", [](const BlockSeeds& s) { return values_out(std::vector<double>(s.values)); })
      .def_property_readonly("gradients",
                             [](const BlockSeeds& s) { return points_out(std::vector<Point3>(s.gradients)); })
      .def_property_readonly("ids", &ids_array, "global ids of the points (uint64)")
      .def_property_readonly("prepared_count", [](const BlockSeeds& s) { return s.prepared.points.size(); })
      .def_property_readonly("precision", [](const BlockSeeds& s) { return s.precision; })
      .def_property_readonly("resolution", [](const BlockSeeds& s) { return s.resolution; })
      .def_property_readonly("flipped", [](const BlockSeeds& s) { return s.flipped; })
      .def_property_readonly("budget_reached", [](const BlockSeeds& s) { return s.budget_reached; })
      .def_property_readonly("outliers", [](const BlockSeeds& s) { return s.outliers; })
      .def_property_readonly("seconds", [](const BlockSeeds& s) { return s.seconds; })
      .def("turned_over",
           [](const BlockSeeds& s) {
             BlockSeeds t = s;
             turn_over(t);
             return t;
           },
           "A copy with the orientation turned over (values, gradients and normals negated).")
      .def("border", [](const BlockSeeds& s, const BlockPlan& p, double halo) { return block_border(p, s, halo); },
           py::arg("plan"), py::arg("merge_halo"),
           "The part of the owned vertices another block's pass 2 can see (within merge_halo of the cell's faces).")
      .def("prepared_part",
           [](const BlockSeeds& s) {
             BlockSeeds h;
             h.block = s.block;
             h.prepared = s.prepared;
             h.resolution = s.resolution;
             h.precision = s.precision;
             h.flipped = s.flipped;
             return h;
           },
           "What the finishing reads of this block (its prepared points, resolution and precision).")
      .def("halo_only",
           [](const BlockSeeds& s) {
             BlockSeeds h;
             h.block = s.block;
             h.halo_points = s.halo_points;
             h.halo_normals = s.halo_normals;
             return h;
           },
           "What the other blocks' votes read of this one (its view of their prepared points).")
      .def(py::pickle([](const BlockSeeds& s) { return to_bytes(encode_block_seeds(s)); },
                      [](const py::bytes& b) { return from_bytes<BlockSeeds>(b, decode_block_seeds); }))
      .def("__repr__", [](const BlockSeeds& s) {
        return "<vitri.BlockSeeds block " + std::to_string(s.block) + ": " + std::to_string(s.points.size()) +
               " vertices, " + std::to_string(s.prepared.points.size()) + " prepared points>";
      });

  py::class_<BlockSurface>(m, "BlockSurface",
                           "Pass 2's result for one block (extract_block()): its triangles over crossings keyed by "
                           "global vertex ids. Picklable.")
      .def_property_readonly("block", [](const BlockSurface& s) { return s.block; })
      .def_property_readonly("crossings", [](const BlockSurface& s) { return s.crossings.size(); })
      .def_property_readonly("triangles", [](const BlockSurface& s) { return s.triangles.size(); })
      .def_property_readonly("unfinished", [](const BlockSurface& s) { return s.unfinished; })
      .def_property_readonly("halo", [](const BlockSurface& s) { return s.halo; }, "the merge halo of its last round")
      .def_property_readonly("rounds", [](const BlockSurface& s) { return s.rounds; })
      .def_property_readonly("seconds", [](const BlockSurface& s) { return s.seconds; })
      .def(py::pickle([](const BlockSurface& s) { return to_bytes(encode_block_surface(s)); },
                      [](const py::bytes& b) { return from_bytes<BlockSurface>(b, decode_block_surface); }))
      .def("__repr__", [](const BlockSurface& s) {
        return "<vitri.BlockSurface block " + std::to_string(s.block) + ": " + std::to_string(s.triangles.size()) +
               " triangles>";
      });

  m.attr("BLOCK_MERGE_HALO_PRECISIONS") = BlockOptions{}.merge_halo_precisions;
  m.attr("BLOCK_MAX_MERGE_HALO_PRECISIONS") = BlockOptions{}.max_merge_halo_precisions;

  m.def("plan_blocks",
        [](py::handle points, py::handle counts, double data_halo_spacings) {
          const std::vector<Point3> pts = points_arg(points, "points");
          BlockOptions o;
          o.counts = counts_arg(counts);
          o.data_halo_spacings = data_halo_spacings;
          if (!(data_halo_spacings > 0) || !std::isfinite(data_halo_spacings))
            throw InvalidArgument("data_halo_spacings must be positive and finite");
          py::gil_scoped_release release;
          return plan_blocks(pts, o);
        },
        py::arg("points"), py::arg("counts") = 2, py::arg("data_halo_spacings") = 24.0);

  m.def("block_budget",
        [](py::handle points, std::size_t memory) {
          const std::vector<Point3> pts = points_arg(points, "points");
          BlockBudget b;
          {
            py::gil_scoped_release release;
            b = plan_block_budget(pts, memory, BlockOptions{});
          }
          py::dict d;
          d["counts"] = b.counts;
          d["largest_block"] = b.largest_block;
          d["block_bytes"] = b.block_bytes;
          d["held_bytes"] = b.held_bytes;
          d["spill"] = b.spill;
          d["fits"] = b.fits;
          return d;
        },
        py::arg("points"), py::arg("memory"));

  m.def("refine_block",
        [](const BlockPlan& plan, int b, py::handle points, py::handle normals, double precision,
           const py::kwargs& kw) {
          if (!(precision >= 0) || !std::isfinite(precision))
            throw InvalidArgument("refine_block: precision must be >= 0 (0: the data's), got " + std::to_string(precision));
          BlockOptions o;
          o.mesher = mesher_options_from(kw, "refine_block");
          o.precision = precision;
          // A block may see no point at all (a cell of the split far from the data, with its halo): its
          // result is empty, as in mesh_in_blocks, never an error.
          const std::vector<Point3> pts = points_arg(points, "points", /*allow_empty=*/true);
          std::vector<Point3> nrm;
          if (!normals.is_none()) nrm = points_arg(normals, "normals", /*allow_empty=*/true);
          if (!nrm.empty() && nrm.size() != pts.size())
            throw InvalidArgument("refine_block: " + std::to_string(nrm.size()) + " normals for " +
                                  std::to_string(pts.size()) + " points");
          py::gil_scoped_release release;
          return refine_block(plan, b, pts, nrm, o);
        },
        py::arg("plan"), py::arg("block"), py::arg("points"), py::arg("normals") = py::none(),
        py::arg("precision") = 0.0);

  m.def("orient_for_blocks",
        [](py::handle points, const py::kwargs& kw) {
          BlockOptions o;
          o.mesher = mesher_options_from(kw, "orient_for_blocks");
          const std::vector<Point3> pts = points_arg(points, "points");
          std::vector<Point3> n;
          {
            py::gil_scoped_release release;
            n = orient_for_blocks(pts, o);
          }
          return points_out(std::move(n));
        },
        py::arg("points"));

  m.def("block_votes",
        [](const BlockPlan& plan, const BlockSeeds& block, py::handle others) {
          const std::vector<const BlockSeeds*> o = seeds_list(others, "others");
          std::vector<double> row;
          {
            py::gil_scoped_release release;
            row = block_votes(plan, block, o);
          }
          return values_out(std::move(row));
        },
        py::arg("plan"), py::arg("block"), py::arg("others"));

  m.def("block_flips",
        [](const std::vector<std::vector<double>>& rows, const std::vector<std::size_t>& counts) {
          return block_flips(rows, counts);
        },
        py::arg("votes"), py::arg("prepared_counts"));

  m.def("extract_block",
        [](const BlockPlan& plan, int b, py::handle seeds, double merge_halo, double max_merge_halo) {
          if (b < 0 || b >= plan.grid.size())
            throw InvalidArgument("extract_block: block " + std::to_string(b) + " of " + std::to_string(plan.grid.size()));
          if (!(merge_halo > 0) || !std::isfinite(merge_halo))
            throw InvalidArgument("extract_block: merge_halo must be positive and finite");
          const std::vector<const BlockSeeds*> s = seeds_list(seeds, "seeds");
          py::gil_scoped_release release;
          return extract_block(plan, b, s, merge_halo, max_merge_halo);
        },
        py::arg("plan"), py::arg("block"), py::arg("seeds"), py::arg("merge_halo"), py::arg("max_merge_halo") = 0.0);

  m.def("stitch_blocks",
        [](py::handle surfaces, py::handle seeds, const std::string& surface, unsigned threads) {
          std::vector<BlockSurface> surf;
          for (py::handle h : surfaces) {
            if (!py::isinstance<BlockSurface>(h))
              throw py::type_error("surfaces: expected BlockSurface, got " + std::string(py::str(py::type::of(h))));
            surf.push_back(h.cast<const BlockSurface&>());
          }
          const std::vector<const BlockSeeds*> s = seeds_list(seeds, "seeds");
          SurfaceKind kind = SurfaceKind::Auto;
          if (surface == "closed") kind = SurfaceKind::Closed;
          else if (surface == "open") kind = SurfaceKind::Open;
          else if (surface != "auto")
            throw InvalidArgument("surface must be 'closed', 'open' or 'auto', got '" + surface + "'");
          BlockStats st;
          SurfaceMesh mesh;
          {
            py::gil_scoped_release release;
            mesh = stitch_blocks(std::move(surf), &st);
            mesh = finish_blocks(std::move(mesh), s, kind, threads, &st);
          }
          py::dict d;
          d["snapped"] = st.snapped;
          d["offset"] = st.offset;
          d["boundary_edges"] = st.boundary_edges;
          d["nonmanifold_edges"] = st.nonmanifold_edges;
          d["precision"] = st.precision;
          d["small_components"] = st.small_components;
          d["handles_cut"] = st.handles_cut;
          d["open"] = st.open;
          d["trimmed_triangles"] = st.trimmed_triangles;
          return py::make_tuple(mesh_out(std::move(mesh)), d);
        },
        py::arg("surfaces"), py::arg("seeds"), py::arg("surface") = "auto", py::arg("threads") = 0u);

  m.def("mesh_in_blocks",
        [](py::handle points, py::handle normals, py::handle counts, double precision, const std::string& spill,
           const py::kwargs& kw) {
          BlockOptions o;
          o.mesher = mesher_options_from(kw, "mesh_in_blocks");
          o.counts = counts_arg(counts);
          o.precision = precision;
          o.spill_directory = spill;
          const std::vector<Point3> pts = points_arg(points, "points");
          std::vector<Point3> nrm;
          if (!normals.is_none()) nrm = points_arg(normals, "normals");
          BlockStats st;
          SurfaceMesh mesh;
          {
            py::gil_scoped_release release;
            mesh = mesh_in_blocks(pts, nrm, o, &st);
          }
          py::dict d;
          d["blocks"] = st.blocks;
          d["unfinished"] = st.unfinished;
          d["flipped"] = st.flipped;
          d["boundary_edges"] = st.boundary_edges;
          d["precision"] = st.precision;
          d["open"] = st.open;
          d["spilled_bytes"] = st.spilled_bytes;
          return py::make_tuple(mesh_out(std::move(mesh)), d);
        },
        py::arg("points"), py::arg("normals") = py::none(), py::arg("counts") = 2, py::arg("precision") = 0.0,
        py::arg("spill") = "");
}

}  // namespace vitri::python
