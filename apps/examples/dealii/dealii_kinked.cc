// deal.II's side of the interop example: a deal.II program that takes fcm's cut-cell rules from
// a rules file (lib/docs/rules_format.md; written by fcm_kinked or `fcm-quadrature export`) for
// its own hexahedral mesh of the same box grid, assembles the embedded problem of
// kinked_problem.h with FE_Q(p)^3 on them (stiffness, mass and body force with the volume rules,
// the traction with the surface rules), solves it and reports the errors against the exact
// solution; optionally compares its nodal values with fcm's solution of the same problem.
//
//   dealii_kinked RULES.fcmr [--degree P] [--compare FCM_SOLUTION.txt] [--tolerance T]
//   dealii_kinked --levelset N Q
//
// The second form measures, for contrast, deal.II's own cut-cell rules on the same body: its
// NonMatching::QuadratureGenerator (Saye's algorithm, QGauss<1>(Q) base) on the N^3 grid with
// the body's level set max over its faces (exact on the faces, not smooth at the kinks), and
// prints the errors of the volume and the centroid it integrates.
//
// The mapping between deal.II's cells and fcm's is explicit and checked: every deal.II cell is
// matched to the fcm cell with the same centre, its eight vertices must be fcm's nodes in VTK
// order, and every quadrature point deal.II maps from the reference points must be the file's
// physical point, with deal.II's JxW equal to the file's physical weight.
// Exit status 0 on success, 1 when a check or the comparison fails, 2 on bad arguments.
#include "kinked_problem.h"

#include <deal.II/base/quadrature.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>
#include <deal.II/non_matching/quadrature_generator.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
// ------------------------------------------------------------------ the rules file

// A rules file in memory: the header and the arrays by name (lib/docs/rules_format.md).
class RulesFile
{
public:
  explicit RulesFile(const std::string &path) : path_(path)
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail("cannot open");
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (bytes_.size() < 16 || std::memcmp(bytes_.data(), "FCMRULES", 8) != 0)
      fail("not an fcm rules file");
    const std::uint64_t hlen = le64(8);
    if (16 + hlen > bytes_.size()) fail("header beyond the end of the file");
    data_ = 16 + hlen;
    std::istringstream hs(std::string(bytes_.data() + 16, hlen));
    boost::property_tree::read_json(hs, header_);
    // version 2 only adds a rule's axis_degree (the points integrate what they did)
    const int version = header_.get<int>("version");
    if (header_.get<std::string>("format") != "fcm-cell-rules" || version < 1 || version > 2)
      fail("not version 1 or 2 of the format");
    if (data_ + header_.get<std::uint64_t>("data_bytes") != bytes_.size())
      fail("truncated (data_bytes does not match the file size)");
    for (const auto &a : header_.get_child("arrays")) {
      Entry e;
      e.dtype = a.second.get<std::string>("dtype");
      e.offset = a.second.get<std::uint64_t>("offset");
      for (const auto &s : a.second.get_child("shape"))
        e.shape.push_back(s.second.get_value<std::uint64_t>());
      if (a.second.get<std::string>("byte_order") != "little") fail("not little-endian");
      arrays_[a.second.get<std::string>("name")] = e;
    }
  }

  const boost::property_tree::ptree &header() const { return header_; }
  bool has(const std::string &name) const { return arrays_.count(name) > 0; }

  // The array `name` as T (its dtype must have T's size), copied out.
  template <typename T>
  std::vector<T> get(const std::string &name, std::size_t *cols = nullptr) const
  {
    const auto it = arrays_.find(name);
    if (it == arrays_.end()) fail("no array " + name);
    const Entry &e = it->second;
    const std::size_t size = e.dtype == "uint8" ? 1 : e.dtype == "int32" ? 4 : 8;
    if (size != sizeof(T)) fail("array " + name + " is " + e.dtype);
    std::size_t n = 1;
    for (const auto s : e.shape)
      n *= s;
    if (cols) *cols = e.shape.size() > 1 ? e.shape[1] : 1;
    if (data_ + e.offset + n * size > bytes_.size()) fail("array " + name + " beyond the file");
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), bytes_.data() + data_ + e.offset, n * size); // little-endian host
    return v;
  }

private:
  struct Entry {
    std::string dtype;
    std::vector<std::uint64_t> shape;
    std::uint64_t offset = 0;
  };

  [[noreturn]] void fail(const std::string &what) const
  {
    throw std::runtime_error(path_ + ": " + what);
  }

  std::uint64_t le64(std::size_t at) const
  {
    std::uint64_t v = 0;
    for (int b = 7; b >= 0; b--)
      v = v << 8 | static_cast<unsigned char>(bytes_[at + b]);
    return v;
  }

  std::string path_;
  std::vector<char> bytes_;
  std::size_t data_ = 0;
  boost::property_tree::ptree header_;
  std::map<std::string, Entry> arrays_;
};

// One rule (volume kind or surface) of every piece: CSR offsets and the point arrays.
struct Rule {
  std::vector<std::int64_t> off;
  std::vector<double> xi, x, w; // reference points, physical points, physical weights
  std::vector<double> wref;     // reference weights (volume rules)
  std::vector<std::uint8_t> flags;
  std::vector<double> normals;

  Rule(const RulesFile &f, const std::string &kind)
  {
    const bool surface = kind == "surface";
    off = f.get<std::int64_t>(kind + "/piece_offsets");
    xi = f.get<double>(kind + "/points_ref");
    x = f.get<double>(kind + "/points_phys");
    w = f.get<double>(kind + (surface ? "/weights" : "/weights_phys"));
    if (surface) {
      normals = f.get<double>("surface/normals");
    } else {
      flags = f.get<std::uint8_t>(kind + "/flags");
      wref = f.get<double>(kind + "/weights_ref");
    }
  }

  // deal.II's quadrature on its unit cell [0,1]^3 for piece p: fcm's reference cell is
  // [-1,1]^3, so points (xi + 1) / 2 and weights w_ref / 8 (surface rules: weight 1; their
  // physical area weights are used as they are).
  Quadrature<3> quadrature(std::int64_t p) const
  {
    std::vector<Point<3>> pts;
    std::vector<double> wts;
    for (std::int64_t j = off[p]; j < off[p + 1]; j++) {
      pts.emplace_back((xi[3 * j] + 1) / 2, (xi[3 * j + 1] + 1) / 2, (xi[3 * j + 2] + 1) / 2);
      wts.push_back(wref.empty() ? 1.0 : wref[j] / 8);
    }
    return Quadrature<3>(pts, wts);
  }
};

// ------------------------------------------------------------------ mesh and cell map

struct Grid {
  std::array<unsigned, 3> n{{0, 0, 0}};
  Point<3> lo, hi;
};

// The box grid of the file: its bounding box and the distinct node coordinates per axis.
Grid grid_of(const RulesFile &f)
{
  Grid g;
  const auto &m = f.header().get_child("mesh");
  std::array<double, 3> lo, hi;
  int d = 0;
  for (const auto &v : m.get_child("lo"))
    lo[d++] = v.second.get_value<double>();
  d = 0;
  for (const auto &v : m.get_child("hi"))
    hi[d++] = v.second.get_value<double>();
  g.lo = Point<3>(lo[0], lo[1], lo[2]);
  g.hi = Point<3>(hi[0], hi[1], hi[2]);
  const auto nodes = f.get<double>("mesh/nodes");
  for (int a = 0; a < 3; a++) {
    std::set<long long> ticks;
    for (std::size_t i = a; i < nodes.size(); i += 3)
      ticks.insert(std::llround((nodes[i] - lo[a]) / (hi[a] - lo[a]) * 1e9));
    g.n[a] = static_cast<unsigned>(ticks.size() - 1);
  }
  return g;
}

// fcm's cell for every deal.II cell (by active cell index), matched by centre and checked
// vertex by vertex against fcm's nodes in VTK order.
std::vector<std::int64_t> cell_map(const RulesFile &f, const Triangulation<3> &tria, const Grid &g)
{
  static const int vtk_of_dealii[8] = {0, 1, 3, 2, 4, 5, 7, 6};
  const auto nodes = f.get<double>("mesh/nodes");
  std::size_t npc = 0;
  const auto cells = f.get<std::int64_t>("mesh/cells", &npc);
  if (npc != 8) throw std::runtime_error("the file's mesh is not of Hex8 cells");
  const double diam = g.lo.distance(g.hi);
  auto key = [&](const Point<3> &c) {
    std::array<long long, 3> k;
    for (int d = 0; d < 3; d++)
      k[d] = std::llround(2.0 * (c[d] - g.lo[d]) / (g.hi[d] - g.lo[d]) * g.n[d]);
    return k;
  };
  std::map<std::array<long long, 3>, std::int64_t> by_centre;
  for (std::size_t c = 0; c < cells.size() / 8; c++) {
    Point<3> centre;
    for (int v = 0; v < 8; v++)
      for (int d = 0; d < 3; d++)
        centre[d] += nodes[3 * cells[8 * c + v] + d] / 8;
    by_centre[key(centre)] = static_cast<std::int64_t>(c);
  }
  std::vector<std::int64_t> map(tria.n_active_cells(), -1);
  for (const auto &cell : tria.active_cell_iterators()) {
    const auto it = by_centre.find(key(cell->center()));
    if (it == by_centre.end())
      throw std::runtime_error("deal.II cell " + std::to_string(cell->active_cell_index()) +
                               " has no fcm cell with its centre");
    for (unsigned v = 0; v < 8; v++) {
      const std::int64_t node = cells[8 * it->second + vtk_of_dealii[v]];
      const Point<3> X(nodes[3 * node], nodes[3 * node + 1], nodes[3 * node + 2]);
      if (cell->vertex(v).distance(X) > 1e-12 * diam)
        throw std::runtime_error("deal.II cell " + std::to_string(cell->active_cell_index()) +
                                 ": vertex " + std::to_string(v) + " is not fcm's node");
    }
    map[cell->active_cell_index()] = it->second;
  }
  return map;
}

// ------------------------------------------------------------------ the problem

struct Errors {
  double l2 = 0, h1 = 0;
};

class KinkedProblem
{
public:
  KinkedProblem(const RulesFile &f, unsigned degree)
      : file_(f), grid_(grid_of(f)), fe_(FE_Q<3>(degree), 3), dofs_(tria_),
        stiffness_(f, "stiffness"), mass_(f, "mass"), surface_(f, "surface")
  {
    GridGenerator::subdivided_hyper_rectangle(tria_, {grid_.n[0], grid_.n[1], grid_.n[2]}, grid_.lo,
                                              grid_.hi);
    fcm_cell_ = cell_map(f, tria_, grid_);
    cls_ = f.get<std::int32_t>("cell_class");
    piece_off_ = f.get<std::int64_t>("cell_piece_offsets");
    for (std::size_t c = 0; c + 1 < piece_off_.size(); c++)
      if (piece_off_[c + 1] - piece_off_[c] > 1)
        throw std::runtime_error("cells split by cuts: one FE per piece is fcm's (XFEM), "
                                 "not this example's");
    dofs_.distribute_dofs(fe_);
  }

  void assemble_and_solve();
  Errors errors() const;
  double compare(const std::string &fcm_solution) const;
  unsigned n() const { return grid_.n[0]; }
  types::global_dof_index n_dofs() const { return dofs_.n_dofs(); }
  double max_point_mismatch() const { return max_point_mismatch_; }

private:
  // FEValues of `rule` on deal.II `cell` (its piece = its fcm cell's only piece), with the
  // mapped points and JxW checked against the file.
  std::unique_ptr<FEValues<3>> values(const Rule &rule, std::int64_t piece,
                                      const DoFHandler<3>::active_cell_iterator &cell, bool volume);
  void assemble_cell(const DoFHandler<3>::active_cell_iterator &cell, std::int64_t piece,
                     FullMatrix<double> &Ke, Vector<double> &fe);

  const RulesFile &file_;
  Grid grid_;
  Triangulation<3> tria_;
  FESystem<3> fe_;
  DoFHandler<3> dofs_;
  MappingQ1<3> mapping_;
  Rule stiffness_, mass_, surface_;
  std::vector<std::int64_t> fcm_cell_, piece_off_;
  std::vector<std::int32_t> cls_;
  Vector<double> u_;
  double max_point_mismatch_ = 0;
};

std::unique_ptr<FEValues<3>> KinkedProblem::values(const Rule &rule, std::int64_t piece,
                                                   const DoFHandler<3>::active_cell_iterator &cell,
                                                   bool volume)
{
  auto fv = std::make_unique<FEValues<3>>(mapping_, fe_, rule.quadrature(piece),
                                          update_values | update_gradients |
                                              update_quadrature_points | update_JxW_values);
  fv->reinit(cell);
  const double size = std::cbrt(cell->measure());
  for (unsigned q = 0; q < fv->n_quadrature_points; q++) {
    const std::int64_t j = rule.off[piece] + q;
    const Point<3> X(rule.x[3 * j], rule.x[3 * j + 1], rule.x[3 * j + 2]);
    max_point_mismatch_ = std::max(max_point_mismatch_, fv->quadrature_point(q).distance(X) / size);
    if (volume) // deal.II's JxW of w_ref / 8 is the file's physical weight
      max_point_mismatch_ =
          std::max(max_point_mismatch_, std::abs(fv->JxW(q) - rule.w[j]) / std::pow(size, 3));
  }
  return fv;
}

void KinkedProblem::assemble_cell(const DoFHandler<3>::active_cell_iterator &cell,
                                  std::int64_t piece, FullMatrix<double> &Ke, Vector<double> &fe)
{
  const FEValuesExtractors::Vector u(0);
  const double lambda = kinked_lambda(), mu = kinked_mu();
  const unsigned nd = fe_.n_dofs_per_cell();
  Ke = 0;
  fe = 0;
  { // stiffness and body force: the stiffness rule (stabilization points included, as fcm)
    const auto fv = values(stiffness_, piece, cell, true);
    for (unsigned q = 0; q < fv->n_quadrature_points; q++) {
      const double w = stiffness_.w[stiffness_.off[piece] + q];
      double f[3];
      const Point<3> &x = fv->quadrature_point(q);
      const double xq[3] = {x[0], x[1], x[2]};
      kinked_force(xq, f);
      for (unsigned i = 0; i < nd; i++) {
        const auto ei = (*fv)[u].symmetric_gradient(i, q);
        const double di = (*fv)[u].divergence(i, q);
        for (unsigned k = 0; k < nd; k++)
          Ke(i, k) += w * (lambda * di * (*fv)[u].divergence(k, q) +
                           2 * mu * (ei * (*fv)[u].symmetric_gradient(k, q)));
        const auto vi = (*fv)[u].value(i, q);
        fe(i) += w * (vi[0] * f[0] + vi[1] * f[1] + vi[2] * f[2]);
      }
    }
  }
  { // mass: the mass rule
    const auto fv = values(mass_, piece, cell, true);
    for (unsigned q = 0; q < fv->n_quadrature_points; q++) {
      const double w = mass_.w[mass_.off[piece] + q] * KINKED_DENSITY;
      for (unsigned i = 0; i < nd; i++)
        for (unsigned k = 0; k < nd; k++)
          Ke(i, k) += w * ((*fv)[u].value(i, q) * (*fv)[u].value(k, q));
    }
  }
  if (surface_.off[piece + 1] > surface_.off[piece]) { // traction: the surface rule
    const auto fv = values(surface_, piece, cell, false);
    for (unsigned q = 0; q < fv->n_quadrature_points; q++) {
      const std::int64_t j = surface_.off[piece] + q;
      double g[3];
      const double xq[3] = {surface_.x[3 * j], surface_.x[3 * j + 1], surface_.x[3 * j + 2]};
      kinked_traction(xq, &surface_.normals[3 * j], g);
      for (unsigned i = 0; i < nd; i++) {
        const auto vi = (*fv)[u].value(i, q);
        fe(i) += surface_.w[j] * (vi[0] * g[0] + vi[1] * g[1] + vi[2] * g[2]);
      }
    }
  }
}

void KinkedProblem::assemble_and_solve()
{
  DynamicSparsityPattern dsp(dofs_.n_dofs());
  DoFTools::make_sparsity_pattern(dofs_, dsp);
  SparsityPattern sp;
  sp.copy_from(dsp);
  SparseMatrix<double> A(sp);
  Vector<double> b(dofs_.n_dofs());
  const unsigned nd = fe_.n_dofs_per_cell();
  FullMatrix<double> Ke(nd, nd);
  Vector<double> fe(nd);
  std::vector<types::global_dof_index> idx(nd);
  for (const auto &cell : dofs_.active_cell_iterators()) {
    const std::int64_t c = fcm_cell_[cell->active_cell_index()];
    if (cls_[c] == 2) continue; // dropped: no points, the cell leaves the system
    assemble_cell(cell, piece_off_[c], Ke, fe);
    cell->get_dof_indices(idx);
    for (unsigned i = 0; i < nd; i++) {
      for (unsigned k = 0; k < nd; k++)
        A.add(idx[i], idx[k], Ke(i, k));
      b(idx[i]) += fe(i);
    }
  }
  for (types::global_dof_index i = 0; i < dofs_.n_dofs(); i++) // DOFs of dropped cells only
    if (A.diag_element(i) == 0.0) A.set(i, i, 1.0);
  SparseDirectUMFPACK solver;
  solver.initialize(A);
  u_.reinit(dofs_.n_dofs());
  solver.vmult(u_, b);
}

Errors KinkedProblem::errors() const
{
  const FEValuesExtractors::Vector u(0);
  Errors e;
  for (const auto &cell : dofs_.active_cell_iterators()) {
    const std::int64_t c = fcm_cell_[cell->active_cell_index()], p = piece_off_[c];
    if (cls_[c] == 2) continue;
    FEValues<3> fv(mapping_, fe_, stiffness_.quadrature(p),
                   update_values | update_gradients | update_quadrature_points);
    fv.reinit(cell);
    std::vector<Tensor<1, 3>> uh(fv.n_quadrature_points);
    std::vector<Tensor<2, 3>> gh(fv.n_quadrature_points);
    fv[u].get_function_values(u_, uh);
    fv[u].get_function_gradients(u_, gh);
    for (unsigned q = 0; q < fv.n_quadrature_points; q++) {
      const std::int64_t j = stiffness_.off[p] + q;
      if (stiffness_.flags[j]) continue; // stabilization points: not the body's
      const Point<3> &x = fv.quadrature_point(q);
      const double xq[3] = {x[0], x[1], x[2]};
      double ue[3], ge[9];
      kinked_exact(xq, ue, ge);
      for (int a = 0; a < 3; a++) {
        e.l2 += stiffness_.w[j] * std::pow(uh[q][a] - ue[a], 2);
        for (int b = 0; b < 3; b++)
          e.h1 += stiffness_.w[j] * std::pow(gh[q][a][b] - ge[3 * a + b], 2);
      }
    }
  }
  e.l2 = std::sqrt(e.l2);
  e.h1 = std::sqrt(e.h1);
  return e;
}

// The largest difference between fcm's nodal displacements and deal.II's at the same vertex,
// relative to the largest of fcm's; every node of fcm's file must be a vertex here.
double KinkedProblem::compare(const std::string &fcm_solution) const
{
  std::map<std::array<long long, 3>, std::array<types::global_dof_index, 3>> at_vertex;
  auto key = [&](const double *x) {
    std::array<long long, 3> k;
    for (int d = 0; d < 3; d++)
      k[d] = std::llround((x[d] - grid_.lo[d]) / (grid_.hi[d] - grid_.lo[d]) * grid_.n[d]);
    return k;
  };
  for (const auto &cell : dofs_.active_cell_iterators())
    for (unsigned v = 0; v < 8; v++) {
      const Point<3> &p = cell->vertex(v);
      const double x[3] = {p[0], p[1], p[2]};
      at_vertex[key(x)] = {{cell->vertex_dof_index(v, 0), cell->vertex_dof_index(v, 1),
                            cell->vertex_dof_index(v, 2)}};
    }
  std::ifstream in(fcm_solution);
  if (!in) throw std::runtime_error(fcm_solution + ": cannot open");
  double x[3], uf[3], diff = 0, scale = 0;
  std::size_t lines = 0;
  while (in >> x[0] >> x[1] >> x[2] >> uf[0] >> uf[1] >> uf[2]) {
    const auto it = at_vertex.find(key(x));
    if (it == at_vertex.end())
      throw std::runtime_error(fcm_solution + ": a node that is no deal.II vertex");
    for (int a = 0; a < 3; a++) {
      diff = std::max(diff, std::abs(u_(it->second[a]) - uf[a]));
      scale = std::max(scale, std::abs(uf[a]));
    }
    lines++;
  }
  if (!lines) throw std::runtime_error(fcm_solution + ": no nodes");
  return diff / scale;
}
// ------------------------------------------------------------------ deal.II's own rules

// The body's level set: the largest of its face functions, each affine in x and zero on its
// face (in the parameter coordinates p = A^-1 (x - c): -s, s - 1, ..., s + t + r - cut).
class BodyLevelSet : public Function<3>
{
public:
  BodyLevelSet()
  {
    const double *a = kinked_A;
    const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                       a[2] * (a[3] * a[7] - a[4] * a[6]);
    inv_ = {{(a[4] * a[8] - a[5] * a[7]) / det, (a[2] * a[7] - a[1] * a[8]) / det,
             (a[1] * a[5] - a[2] * a[4]) / det, (a[5] * a[6] - a[3] * a[8]) / det,
             (a[0] * a[8] - a[2] * a[6]) / det, (a[2] * a[3] - a[0] * a[5]) / det,
             (a[3] * a[7] - a[4] * a[6]) / det, (a[1] * a[6] - a[0] * a[7]) / det,
             (a[0] * a[4] - a[1] * a[3]) / det}};
  }

  double value(const Point<3> &x, const unsigned = 0) const override
  {
    Tensor<1, 3> g;
    return face(x, g);
  }

  Tensor<1, 3> gradient(const Point<3> &x, const unsigned = 0) const override
  {
    Tensor<1, 3> g;
    face(x, g);
    return g;
  }

private:
  // The largest face function at x, and its gradient in g.
  double face(const Point<3> &x, Tensor<1, 3> &g) const
  {
    double p[3];
    for (int i = 0; i < 3; i++) {
      p[i] = 0;
      for (int j = 0; j < 3; j++)
        p[i] += inv_[3 * i + j] * (x[j] - kinked_c[j]);
    }
    double best = -1e300;
    for (int f = 0; f < 7; f++) {
      double v, dp[3] = {0, 0, 0}; // the face function and its gradient in p
      if (f < 6) {
        const int i = f / 2;
        v = f % 2 ? p[i] - 1 : -p[i];
        dp[i] = f % 2 ? 1 : -1;
      } else {
        v = p[0] + p[1] + p[2] - KINKED_CUT;
        dp[0] = dp[1] = dp[2] = 1;
      }
      if (v > best) {
        best = v;
        for (int j = 0; j < 3; j++)
          g[j] = inv_[j] * dp[0] + inv_[3 + j] * dp[1] + inv_[6 + j] * dp[2];
      }
    }
    return best;
  }

  std::array<double, 9> inv_;
};

// The volume and centroid errors of deal.II's inside rules on the N^3 grid; 0 on success.
int levelset_study(unsigned n, unsigned q)
{
  // exact volume and centroid from the body's tetrahedra
  double xyz[3 * KINKED_NODES], vol = 0, mom[3] = {0, 0, 0};
  long long tets[4 * KINKED_TETS];
  kinked_body(xyz, tets);
  for (int t = 0; t < KINKED_TETS; t++) {
    const double *v[4];
    for (int k = 0; k < 4; k++)
      v[k] = xyz + 3 * tets[4 * t + k];
    Tensor<2, 3> e;
    for (int k = 0; k < 3; k++)
      for (int d = 0; d < 3; d++)
        e[k][d] = v[k + 1][d] - v[0][d];
    const double vt = std::abs(determinant(e)) / 6;
    vol += vt;
    for (int d = 0; d < 3; d++)
      mom[d] += vt * (v[0][d] + v[1][d] + v[2][d] + v[3][d]) / 4;
  }
  Triangulation<3> tria;
  GridGenerator::subdivided_hyper_rectangle(tria, {n, n, n}, Point<3>(0, 0, 0), Point<3>(1, 1, 1));
  const BodyLevelSet phi;
  const hp::QCollection<1> base{QGauss<1>(q)};
  NonMatching::QuadratureGenerator<3> gen(base);
  double v = 0, m[3] = {0, 0, 0};
  for (const auto &cell : tria.active_cell_iterators()) {
    const BoundingBox<3> box(std::make_pair(cell->vertex(0), cell->vertex(7)));
    gen.generate(phi, box);
    const Quadrature<3> &in = gen.get_inside_quadrature();
    for (unsigned k = 0; k < in.size(); k++) {
      v += in.weight(k);
      for (int d = 0; d < 3; d++)
        m[d] += in.weight(k) * in.point(k)[d];
    }
  }
  double cerr = 0;
  for (int d = 0; d < 3; d++)
    cerr = std::max(cerr, std::abs(m[d] / v - mom[d] / vol));
  std::printf("dealii_kinked --levelset: N = %u, QGauss<1>(%u): volume %.15g (exact %.15g, "
              "relative error %.2e), centroid error %.2e\n",
              n, q, v, vol, std::abs(v - vol) / vol, cerr);
  return 0;
}
} // namespace

int main(int argc, char **argv)
{
  std::string rules, compare;
  unsigned degree = 1;
  double tolerance = 1e-10;
  if (argc == 4 && std::string(argv[1]) == "--levelset") {
    const int n = std::atoi(argv[2]), q = std::atoi(argv[3]);
    if (n < 1 || n > 256 || q < 1 || q > 10) {
      std::cerr << "dealii_kinked --levelset N Q: N in [1, 256], Q in [1, 10]\n";
      return 2;
    }
    return levelset_study(static_cast<unsigned>(n), static_cast<unsigned>(q));
  }
  for (int i = 1; i < argc; i++) {
    const std::string a = argv[i];
    if (a == "--degree" && i + 1 < argc)
      degree = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (a == "--compare" && i + 1 < argc)
      compare = argv[++i];
    else if (a == "--tolerance" && i + 1 < argc)
      tolerance = std::atof(argv[++i]);
    else if (rules.empty() && a[0] != '-')
      rules = a;
    else {
      std::cerr << "usage: dealii_kinked RULES.fcmr [--degree P] [--compare FCM_SOLUTION.txt] "
                   "[--tolerance T]\n";
      return 2;
    }
  }
  if (rules.empty() || degree < 1 || degree > 4 || !(tolerance > 0)) {
    std::cerr << "dealii_kinked: a rules file, --degree in [1, 4] and --tolerance > 0 needed\n";
    return 2;
  }
  try {
    const RulesFile file(rules);
    KinkedProblem problem(file, degree);
    problem.assemble_and_solve();
    const Errors e = problem.errors();
    std::printf("dealii_kinked: N = %u, Q%u, %llu DOFs, L2 error %.6e, H1 error %.6e, point/JxW "
                "mismatch %.1e\n",
                problem.n(), degree, static_cast<unsigned long long>(problem.n_dofs()), e.l2, e.h1,
                problem.max_point_mismatch());
    if (!(problem.max_point_mismatch() <= 1e-12)) {
      std::fprintf(stderr,
                   "dealii_kinked: deal.II's mapped points or JxW differ from the file's\n");
      return 1;
    }
    if (!compare.empty()) {
      const double d = problem.compare(compare);
      std::printf("dealii_kinked: largest difference to fcm's solution %.3e (relative; tolerance "
                  "%.1e)\n",
                  d, tolerance);
      if (!(d <= tolerance)) return 1;
    }
  } catch (const std::exception &ex) {
    std::fprintf(stderr, "dealii_kinked: %s\n", ex.what());
    return 1;
  }
  return 0;
}
