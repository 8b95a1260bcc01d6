// Tetrahedral remesh of the Colin27 brain surface for cohaptic's brain scene.
// Gmsh 4.8 script. It reads brain_surface.stl (the FreeSurfer surface
// ../shared/data/colin27/brain_surface.asc written as STL, millimetres, with the
// supracerebellar corridor carved into it) from the directory of this script.
// deploy/remesh-brain.sh writes that STL (see its header for the corridor), runs
//   gmsh remesh.geo -3 -nt 1 -format msh41 -o brain.msh
// and removes the $Parametrizations section (the reparametrisation of the discrete
// surfaces, which cohaptic does not use: it would triple the file).
//
// Two modes:
//  - uniform (fine = 0, the default): size h everywhere. This makes brain.msh.
//      gmsh remesh.geo -setnumber h 8 ...
//  - graded (fine > 0): size `fine` in the tools' working region (each 7 mm sphere swept
//    along its press path, below) and the tissue within `margin` mm of it; the size then
//    grows linearly to h over the next `grow` mm, and is h beyond. With near > 0, a finer
//    size `near` where the tips touch: within `nearMargin` mm of the swept spheres, growing
//    to `fine` over the next `nearGrow` mm. This makes brain_graded.msh (fine = 2.5,
//    near = 1.2) and its convergence reference (fine = 1.25, near = 0.6).
//      gmsh remesh.geo -setnumber fine 2.5 -setnumber near 1.2 ...
DefineConstant[
  h = {9, Name "Element size (mm); in graded mode, the size far from the tools"},
  fine = {0, Name "Graded mode: the size near the tools (mm); 0 = uniform size h"},
  margin = {20, Name "Graded mode: size fine up to this distance from the tools' spheres (mm)"},
  grow = {30, Name "Graded mode: distance over which the size grows from fine to h (mm)"},
  near = {0, Name "Graded mode: a finer size where the tips touch (mm); 0 = none"},
  nearMargin = {3, Name "Graded mode: size near up to this distance from the tools' spheres (mm)"},
  nearGrow = {5, Name "Graded mode: distance over which the size grows from near to fine (mm)"}
];

Merge "brain_surface.stl";

// The surface is smooth: split it into parametrisable patches (feature angle 40 deg,
// boundaries kept, patches forced parametrisable, curves not split), then build a
// geometry on which the surface can be remeshed at a new size.
ClassifySurfaces{40 * Pi / 180, 1, 1, 180 * Pi / 180};
CreateGeometry;

Surface Loop(1) = Surface{:};
Volume(1) = {1};
Physical Volume("brain", 1) = {1};   // only the tetrahedra are saved

If (fine > 0)
  // The tools' press paths (surgeon_a.yaml, surgeon_b.yaml), mm: from the centre where each
  // tool stops before pressing to its deepest centre, 6 mm along the unit press direction.
  // Both tools are spheres of radius 7 mm.
  toolRadius = 7;
  paths() = {-15.4, -79.9, -45.0,   -15.943, -75.736, -49.285,    // A, into the cerebellum
               0.9, -89.8, -34.5,     0.119, -85.715, -30.175};   // B, into the occipital lobe
  For i In {0:1}
    x0 = paths(6 * i);     y0 = paths(6 * i + 1); z0 = paths(6 * i + 2);
    dx = paths(6 * i + 3) - x0; dy = paths(6 * i + 4) - y0; dz = paths(6 * i + 5) - z0;
    // Field 10i+2: the distance from (x, y, z) to the path, P0 + t d with 0 <= t <= 1. t (the
    // nearest point) is written out three times: a MathEval field that reads another one
    // (F1) hangs in this build.
    t = Sprintf("min(1, max(0, ((x - (%g))*(%g) + (y - (%g))*(%g) + (z - (%g))*(%g)) / %g))",
                x0, dx, y0, dy, z0, dz, dx * dx + dy * dy + dz * dz);
    Field[10 * i + 2] = MathEval;
    Field[10 * i + 2].F = Sprintf(StrCat("sqrt((x - (%g) - (%g)*", t, ")^2 + (y - (%g) - (%g)*", t,
                                        ")^2 + (z - (%g) - (%g)*", t, ")^2)"), x0, dx, y0, dy, z0, dz);
    // Field 10i+3: the size, fine up to toolRadius + margin from the path, h from
    // toolRadius + margin + grow on, linear in between.
    Field[10 * i + 3] = Threshold;
    Field[10 * i + 3].InField = 10 * i + 2;
    Field[10 * i + 3].SizeMin = fine;
    Field[10 * i + 3].SizeMax = h;
    Field[10 * i + 3].DistMin = toolRadius + margin;
    Field[10 * i + 3].DistMax = toolRadius + margin + grow;
    // Field 10i+4: near up to toolRadius + nearMargin from the path, then growing at the
    // rate that reaches fine nearGrow mm further (on to h, where field 10i+3 is the smaller).
    // Without near, h everywhere: the Min below ignores it.
    Field[10 * i + 4] = Threshold;
    Field[10 * i + 4].InField = 10 * i + 2;
    Field[10 * i + 4].SizeMin = (near > 0) ? near : h;
    Field[10 * i + 4].SizeMax = h;
    Field[10 * i + 4].DistMin = toolRadius + nearMargin;
    Field[10 * i + 4].DistMax = toolRadius + nearMargin + ((near > 0) ? nearGrow * (h - near) / (fine - near) : 1);
  EndFor
  Field[30] = Min;
  Field[30].FieldsList = {3, 4, 13, 14};
  Background Field = 30;
  Mesh.CharacteristicLengthMin = (near > 0) ? near : fine;
  Mesh.CharacteristicLengthMax = h;
Else
  Mesh.CharacteristicLengthMin = h;
  Mesh.CharacteristicLengthMax = h;
EndIf
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
Mesh.Algorithm = 6;          // Frontal-Delaunay for the surface patches
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;           // Gmsh's tetrahedral optimiser (Netgen's is not in Debian's build)
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;             // ASCII
