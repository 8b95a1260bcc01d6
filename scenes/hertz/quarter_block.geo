// The quarter of a large elastic block that `cohaptic-lab hertz` presses a sphere into
// (lab/hertz.h): [0, s]^2 x [-s, 0] in millimetres, the sphere's contact point at the origin
// where the two symmetry planes x = 0 and y = 0 meet the top face z = 0. Gmsh 4.8 script.
//
// The element size is `fine` R within fine / growth of the contact point and `growth` times
// the distance beyond: the cells keep the same size relative to their distance from the
// contact, the grading a point-like load's field asks for (its strains fall off with the
// distance). A box mesh's tensor-product grading spends most of its nodes on fine columns
// far from the contact; this one does not.
//
// `cohaptic-lab hertz` meshes it with gmsh at the sizes it is given (--gmsh-fine, in R; by
// default 0.05 and 0.025) and growth 0.07, as
//   gmsh quarter_block.geo -3 -nt 1 -setnumber fine 0.05 -setnumber growth 0.07 -o quarter_block.msh
SetFactory("OpenCASCADE");
DefineConstant[ R = {10, Name "Sphere radius (mm)"} ];
DefineConstant[ side_over_R = {40, Name "Side of the quarter block, over R (at least 20)"} ];
DefineConstant[ fine = {0.015, Name "Element size at the contact, over R"} ];
DefineConstant[ growth = {0.06, Name "Element size per unit distance from the contact"} ];

side = side_over_R * R;
Box(1) = {0, 0, -side, side, side, side};
Physical Volume("block", 1) = {1};   // only the tetrahedra are saved

Point(100) = {0, 0, 0};
Field[1] = Distance;
Field[1].PointsList = {100};
Field[2] = MathEval;
Field[2].F = Sprintf("Max(%g, %g * F1)", fine * R, growth);
Background Field = 2;

Mesh.CharacteristicLengthMax = side;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
Mesh.Algorithm = 6;          // Frontal-Delaunay for the faces
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;             // ASCII
