// The scene's description of a laparoscopy tissue (`model: home_spring`,
// docs/laparoscopy.md) and of an instrument tool (`shape: probe` or `shape:
// forceps`), as loaded: plain data, validated by the scene loader (parse_home_spring.h).
//
// The tissue is a triangle surface (a FreeSurfer .asc file, or a generated horizontal grid
// facing +z) whose vertices are held by the paper's home springs (k1) and 1-ring springs
// (k2); the display deforms it by Eq. 1 or by FFD (tissue_display.h). An instrument's shaft
// passes through its trocar pivot. Units: m, N/m, N s/m, rad.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

namespace cohaptic {

/// A flat sheet in the plane z = min.z: divisions.x by divisions.y rectangular cells over
/// [min.x, min.x + size.x] x [min.y, min.y + size.y], two triangles each, facing +z.
struct TissueGridSpec {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();   ///< [m]
  Eigen::Vector2d size = Eigen::Vector2d::Ones();  ///< [m], both > 0
  Eigen::Vector2i divisions = Eigen::Vector2i::Ones();
};

enum class TissueDisplayKind { polynomial, ffd };

struct HomeSpringObjectSpec {
  std::filesystem::path
      surface_file;  ///< FreeSurfer .asc (resolved against the scene's directory), or
  std::optional<TissueGridSpec> grid;  ///< a generated sheet: exactly one of the two
  double home_stiffness = 0;           ///< k1 [N/m], > 0
  double neighbour_stiffness = 0;      ///< k2 [N/m], >= 0
  double damping = 0;       ///< c [N s/m], >= 0: the dashpot beside each home spring (0: none)
  double patch_radius = 0;  ///< the IR's patch: triangles within it of the contact vertex [m]
  TissueDisplayKind display = TissueDisplayKind::polynomial;
  double display_radius = 0;  ///< R of Eq. 1 (and the FFD lattice's margin) [m]
};

/// A probe's or forceps' shaft through its trocar, and the forceps' jaws (forceps_jaws.h).
struct InstrumentSpec {
  Eigen::Vector3d trocar = Eigen::Vector3d::Zero();  ///< the pivot [m]
  Eigen::Vector3d opening =
      Eigen::Vector3d::UnitX();  ///< forceps: the jaws open along it, projected off the shaft
  double jaw_length = 0.01;      ///< forceps [m]
  double open_angle = 0.5;       ///< forceps: each jaw's angle from the shaft when open [rad]
  double closing_step = 0.02;    ///< forceps: closing per server step while button 0 is held [rad]
};

}  // namespace cohaptic
