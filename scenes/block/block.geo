// An elastic block with two places graded for a 10 mm sphere each (scenes/block/two_spheres.yaml):
// [-100, 100] x [-60, 60] x [-100, 0] in millimetres, its top face z = 0, the two contact
// points at (-25, 0, 0) and (25, 0, 0). Gmsh 4.8 script, meshed when a scene loads it
// (`mesh: {gmsh: ...}` in docs/scene-files.md), with its parameters set there.
//
// The element size is `fine` (mm) within fine / growth of either contact point and `growth`
// times the distance beyond it, up to `coarse` (mm): the cells keep the same size relative
// to their distance from the contact, as a point-like load's field asks (its strains fall
// off with the distance).
SetFactory("OpenCASCADE");
DefineConstant[ fine = {0.6, Name "Element size at the contact points (mm)"} ];
DefineConstant[ growth = {0.1, Name "Element size per unit distance from them"} ];
DefineConstant[ coarse = {20, Name "Largest element size (mm)"} ];

Box(1) = {-100, -60, -100, 200, 120, 100};
Physical Volume("block", 1) = {1};   // only the tetrahedra are saved

Point(100) = {-25, 0, 0};
Point(101) = {25, 0, 0};
Field[1] = Distance;
Field[1].PointsList = {100, 101};
Field[2] = MathEval;
Field[2].F = Sprintf("Min(%g, Max(%g, %g * F1))", coarse, fine, growth);
Background Field = 2;

Mesh.CharacteristicLengthMax = coarse;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
Mesh.Algorithm = 6;          // Frontal-Delaunay for the faces
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;             // ASCII
