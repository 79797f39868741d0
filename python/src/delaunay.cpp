// vitri.Delaunay: the exact, dynamic Delaunay tetrahedralization of points inside a box (delaunay/).
// Vertex ids are the library's: the 8 box corners are 0..7 (corner k: x from bit 0, y from bit 1, z from
// bit 2, the maximum when the bit is set), then one id per inserted point, never reused.
#include "common.hpp"

#include "vitri/core/box.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>

namespace vitri::python {
namespace {

struct Delaunay {
  std::unique_ptr<Triangulation> tr;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
};

/// The box of `vitri tetrahedralize`: the points' bounding box enlarged by 2 about its centre, a flat
/// axis getting the largest extent of the others.
Box3 default_box(const std::vector<Point3>& points) {
  Box3 bb;
  for (const Point3& p : points) bb.extend(p);
  if (bb.empty()) throw InvalidArgument("Delaunay: give points or a box");
  const Point3 e = bb.extent();
  double m = std::max({e.x, e.y, e.z});
  if (m == 0.0) m = std::max(1.0, std::abs(bb.lo.x) + std::abs(bb.lo.y) + std::abs(bb.lo.z));
  const Point3 c = bb.center();
  const Point3 h{0.5 * (e.x > 0 ? e.x : m), 0.5 * (e.y > 0 ? e.y : m), 0.5 * (e.z > 0 ? e.z : m)};
  return Box3{c - h, c + h}.scaled(2.0);
}

py::array insert_many(Delaunay& d, const std::vector<Point3>& pts, double min_distance) {
  std::vector<std::uint32_t> ids(pts.size());
  without_gil(*d.mutex, [&] {
    const std::vector<InsertResult> r = d.tr->insert_points(pts, min_distance);
    for (std::size_t i = 0; i < r.size(); ++i) ids[i] = r[i].status == InsertStatus::Inserted ? r[i].vertex : kNoVertex;
  });
  return ids_out(std::move(ids));
}

py::object id_or_none(const InsertResult& r) {
  return r.status == InsertStatus::Inserted ? py::object(py::int_(r.vertex)) : py::object(py::none());
}

}  // namespace

void bind_delaunay(py::module_& m) {
  py::class_<Delaunay> cls(
      m, "Delaunay",
      "The exact Delaunay tetrahedralization of points inside a box (symbolic perturbation: unique for any "
      "input), dynamic: insertion (bulk or one by one), removal, moves, point location.\n"
      "Vertex ids: the 8 box corners are 0..7 (corner k: x from bit 0, y from bit 1, z from bit 2, the "
      "maximum when set), inserted points get new ids, never reused. Tetrahedra are positively oriented.");
  cls.def(py::init([](py::handle points, py::handle box, bool keep_history, unsigned threads) {
            std::vector<Point3> pts;
            if (!points.is_none()) pts = points_arg(points, "points");
            Box3 b;
            if (box.is_none()) {
              b = default_box(pts);
            } else {
              const std::vector<Point3> corners = points_arg(box, "box");
              if (corners.size() != 2) throw InvalidArgument("box: expected [[xmin, ymin, zmin], [xmax, ymax, zmax]]");
              b = Box3{corners[0], corners[1]};
            }
            TriangulationOptions o;
            o.keep_history = keep_history;
            o.threads = threads;
            Delaunay d;
            d.tr = std::make_unique<Triangulation>(b, o);
            return d;
          }),
          py::arg("points") = py::none(), py::kw_only(), py::arg("box") = py::none(),
          py::arg("keep_history") = true, py::arg("threads") = 1u,
          "A tetrahedralization of the box's 8 corners. box: [[xmin, ymin, zmin], [xmax, ymax, zmax]]; "
          "default: the bounding box of `points` enlarged by 2 about its centre (as `vitri tetrahedralize`). "
          "`points`, when given, only sets that box: insert them with insert(). keep_history: the history "
          "DAG (O(log n) location; needed for fast edits); threads: for bulk insertion without history.")
      .def("insert",
           [](Delaunay& d, py::handle points, double min_distance) {
             return insert_many(d, points_arg(points, "points", true), min_distance);
           },
           py::arg("points"), py::arg("min_distance") = 0.0,
           "Inserts (n, 3) points in bulk (spatially sorted). Returns their vertex ids (n,) uint32, "
           "0xFFFFFFFF for a point rejected as a duplicate or closer than min_distance to a vertex. "
           "Raises InvalidPoint (its row) for a point not strictly inside the box, nothing inserted.")
      .def("insert_point",
           [](Delaunay& d, py::handle p, double min_distance) {
             const Point3 q = point_arg(p, "point");
             return id_or_none(without_gil(*d.mutex, [&] { return d.tr->insert(q, min_distance); }));
           },
           py::arg("point"), py::arg("min_distance") = 0.0,
           "Inserts one point; returns its vertex id, or None when it is rejected (duplicate, too close).")
      .def("remove",
           [](Delaunay& d, std::uint32_t v) { without_gil(*d.mutex, [&] { d.tr->remove(v); }); }, py::arg("vertex"),
           "Removes a vertex (not a box corner): the result is the Delaunay tetrahedralization of the others.")
      .def("move",
           [](Delaunay& d, std::uint32_t v, py::handle p, double min_distance) {
             const Point3 q = point_arg(p, "point");
             const InsertResult r = without_gil(*d.mutex, [&] { return d.tr->move(v, q, min_distance); });
             return r.status == InsertStatus::Inserted;
           },
           py::arg("vertex"), py::arg("point"), py::arg("min_distance") = 0.0,
           "Moves a vertex (it keeps its id). False (nothing changed) when `point` is too close to another vertex.")
      .def("locate",
           [](Delaunay& d, py::handle p) {
             const Point3 q = point_arg(p, "point");
             return without_gil(*d.mutex, [&] {
               if (!d.tr->box().contains(q)) throw InvalidArgument("locate: the point is outside the box");
               const TetId t = d.tr->locate(q);
               return d.tr->tet_vertices(t);
             });
           },
           py::arg("point"), "The 4 vertex ids of a tetrahedron containing `point` (closed; inside the box).")
      .def("tetrahedra",
           [](Delaunay& d) {
             std::vector<std::uint32_t> out;
             without_gil(*d.mutex, [&] {
               out.reserve(4 * d.tr->num_tetrahedra());
               d.tr->for_each_tetrahedron([&](TetId t) {
                 for (int i = 0; i < 4; ++i) out.push_back(d.tr->tet_vertex(t, i));
               });
             });
             return ids_out(std::move(out)).attr("reshape")(-1, 4);
           },
           "The live tetrahedra as an (m, 4) uint32 array of vertex ids, each positively oriented.")
      .def("neighbors",
           [](Delaunay& d) {
             std::vector<std::uint32_t> out;
             without_gil(*d.mutex, [&] {
               std::vector<TetId> live = d.tr->live_tetrahedra();
               std::vector<std::uint32_t> row(d.tr->tet_capacity(), kNoTet);
               for (std::size_t r = 0; r < live.size(); ++r) row[live[r]] = std::uint32_t(r);
               out.reserve(4 * live.size());
               for (const TetId t : live)
                 for (int i = 0; i < 4; ++i) {
                   const TetId n = d.tr->tet_neighbor(t, i);
                   out.push_back(n == kNoTet ? kNoTet : row[n]);
                 }
             });
             return ids_out(std::move(out)).attr("reshape")(-1, 4);
           },
           "(m, 4) uint32: row k, column i is the row (in tetrahedra()) of the tetrahedron across the face "
           "opposite vertex i of tetrahedron k, 0xFFFFFFFF on the hull.")
      .def("vertices",
           [](Delaunay& d) {
             std::vector<std::uint32_t> ids;
             std::vector<Point3> pos;
             without_gil(*d.mutex, [&] {
               for (VertexId v = 0; v < d.tr->vertex_capacity(); ++v)
                 if (d.tr->is_vertex(v)) {
                   ids.push_back(v);
                   pos.push_back(d.tr->point(v));
                 }
             });
             return py::make_tuple(ids_out(std::move(ids)), points_out(std::move(pos)));
           },
           "(ids (k,) uint32, positions (k, 3)) of the live vertices, box corners included.")
      .def("point",
           [](Delaunay& d, std::uint32_t v) {
             if (!d.tr->is_vertex(v)) throw InvalidArgument("vertex " + std::to_string(v) + " is not live");
             return points_out({d.tr->point(v)}).attr("reshape")(3);
           },
           py::arg("vertex"), "The position of a live vertex.")
      .def("is_valid",
           [](Delaunay& d) {
             return without_gil(*d.mutex, [&] {
               try {
                 d.tr->verify_topology();
                 d.tr->verify_delaunay();
               } catch (const std::logic_error&) {
                 return false;
               }
               return true;
             });
           },
           "Checks the topology (neighbour symmetry, orientation, links) and the exact empty-sphere property.")
      .def_property_readonly("box", [](Delaunay& d) {
             return points_out({d.tr->box().lo, d.tr->box().hi});
           }, "[[xmin, ymin, zmin], [xmax, ymax, zmax]]")
      .def_property_readonly("num_vertices", [](Delaunay& d) { return d.tr->num_vertices(); },
                             "Live vertices, the 8 corners included.")
      .def_property_readonly("num_tetrahedra", [](Delaunay& d) { return d.tr->num_tetrahedra(); })
      .def("__len__", [](Delaunay& d) { return d.tr->num_vertices(); });
}

}  // namespace vitri::python
