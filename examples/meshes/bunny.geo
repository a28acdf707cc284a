// A blobby, bunny-like body (units: metres, about 0.5 m long): body, head, two ears, tail, feet.
// Meshed by the fem driver with gmsh (-mesh examples/meshes/bunny.geo -mesh_size H).
SetFactory("OpenCASCADE");
Sphere(1) = {0, 0, 0.12, 0.14};          // body
Dilate {{0, 0, 0.12}, {1.35, 1.0, 0.9}} { Volume{1}; }
Sphere(2) = {0.2, 0, 0.27, 0.085};        // head
Cylinder(3) = {0.21, 0.035, 0.32, -0.03, 0.02, 0.17, 0.022};   // ears
Cylinder(4) = {0.21, -0.035, 0.32, -0.03, -0.02, 0.17, 0.022};
Sphere(5) = {-0.2, 0, 0.16, 0.045};       // tail
Sphere(6) = {0.1, 0.08, 0.03, 0.05};      // front feet
Sphere(7) = {0.1, -0.08, 0.03, 0.05};
Sphere(8) = {-0.1, 0.1, 0.04, 0.07};      // hind legs
Sphere(9) = {-0.1, -0.1, 0.04, 0.07};
BooleanUnion{ Volume{1}; Delete; }{ Volume{2:9}; Delete; }
Mesh.Optimize = 1;
