// Coarse tetrahedral remesh of the Colin27 brain surface for cohaptic's brain scene.
// Gmsh 4.8 script. It reads brain_surface.stl (the FreeSurfer surface
// ../shared/data/colin27/brain_surface.asc written as STL, millimetres, with the
// supracerebellar corridor carved into it) from the directory of this script.
// deploy/remesh-brain.sh writes that STL (see its header for the corridor), runs
//   gmsh remesh.geo -3 -nt 1 -format msh41 -o brain.msh
// and removes the $Parametrizations section (the reparametrisation of the discrete
// surfaces, which cohaptic does not use: it would triple the file).
// Override the element size with: gmsh remesh.geo -setnumber h 8 ...
DefineConstant[ h = {9, Name "Element size (mm)"} ];

Merge "brain_surface.stl";

// The surface is smooth: split it into parametrisable patches (feature angle 40 deg,
// boundaries kept, patches forced parametrisable, curves not split), then build a
// geometry on which the surface can be remeshed at a new size.
ClassifySurfaces{40 * Pi / 180, 1, 1, 180 * Pi / 180};
CreateGeometry;

Surface Loop(1) = Surface{:};
Volume(1) = {1};
Physical Volume("brain", 1) = {1};   // only the tetrahedra are saved

Mesh.CharacteristicLengthMin = h;
Mesh.CharacteristicLengthMax = h;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.Algorithm = 6;          // Frontal-Delaunay for the surface patches
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;           // Gmsh's tetrahedral optimiser (Netgen's is not in Debian's build)
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;             // ASCII
