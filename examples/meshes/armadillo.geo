// An armadillo-like body (units: metres, about 1 m tall): torso, head with ears and snout, arms,
// legs and a tail. Meshed by the fem driver with gmsh (-mesh examples/meshes/armadillo.geo -mesh_size H).
SetFactory("OpenCASCADE");
Sphere(1) = {0, 0, 0.55, 0.2};             // torso
Dilate {{0, 0, 0.55}, {0.9, 0.7, 1.4}} { Volume{1}; }
Sphere(2) = {0, 0.03, 0.95, 0.11};          // head
Cylinder(3) = {0, 0.1, 0.93, 0, 0.1, 0, 0.045};          // snout
Cylinder(4) = {0.06, 0, 1.0, 0.06, -0.02, 0.14, 0.03};   // ears
Cylinder(5) = {-0.06, 0, 1.0, -0.06, -0.02, 0.14, 0.03};
Cylinder(6) = {0.15, 0, 0.72, 0.22, 0.08, -0.12, 0.05};  // arms
Cylinder(7) = {-0.15, 0, 0.72, -0.22, 0.08, -0.12, 0.05};
Sphere(8) = {0.37, 0.08, 0.6, 0.06};                    // hands
Sphere(9) = {-0.37, 0.08, 0.6, 0.06};
Cylinder(10) = {0.1, 0, 0.35, 0.04, 0.02, -0.33, 0.07};  // legs
Cylinder(11) = {-0.1, 0, 0.35, -0.04, 0.02, -0.33, 0.07};
Box(12) = {0.06, -0.06, 0.0, 0.14, 0.2, 0.05};           // feet
Box(13) = {-0.2, -0.06, 0.0, 0.14, 0.2, 0.05};
Cylinder(14) = {0, -0.12, 0.35, 0, -0.3, -0.25, 0.04};   // tail
BooleanUnion{ Volume{1}; Delete; }{ Volume{2:14}; Delete; }
Mesh.Optimize = 1;
