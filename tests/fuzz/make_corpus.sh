#!/usr/bin/env bash
# Seed corpora of the fuzz targets: make_corpus.sh BUILD_DIR OUT_DIR writes OUT_DIR/gmsh,
# tetgen, surface, voxels, scene and checkpoint with small valid inputs of each format: MSH 4.1 and 2.2 files
# of every supported element type with skipped sections and boundary elements, TetGen pairs
# (0- and 1-based, attributes, markers, comments; .node NUL .ele, as fcm-fuzz-tetgen reads
# them), surfaces (a format byte, then an OBJ, OFF, STL or PLY file, as fcm-fuzz-surface
# reads them), the example scenes and the built-in default, and checkpoints of the checkpoint
# target's scene written by BUILD_DIR/fcm-fuzz-seed-checkpoint (a build with -DFCM_FUZZ=ON).
set -euo pipefail
[ $# -eq 2 ] || { sed -n '2,8p' "$0"; exit 2; }
build=$1
out=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
mkdir -p "$out/gmsh" "$out/tetgen" "$out/scene" "$out/checkpoint" "$out/surface"

# ---------------------------------------------------------------- Gmsh MSH
cat > "$out/gmsh/hex8_v22.msh" <<'EOF'
$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "solid"
$EndPhysicalNames
$Nodes
9
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
9 5 5 5
$EndNodes
$Elements
3
1 15 2 0 1 1
2 2 2 0 1 1 2 3
3 5 2 1 1 1 2 3 4 5 6 7 8
$EndElements
$NodeData
1
"ignored"
0
0
$EndNodeData
EOF
cat > "$out/gmsh/tet4_v41.msh" <<'EOF'
$MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 0 1
1 0 0 0 1 1 1 0 0
$EndEntities
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
1 2 1 2
3 1 4 2
1 1 2 3 4
2 2 3 4 5
$EndElements
EOF
cat > "$out/gmsh/tet10_v41.msh" <<'EOF'
$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
2 10 10 100
2 1 1 4
10
20
30
40
0 0 0 0.5 0.5
1 0 0 0.5 0.5
0 1 0 0.5 0.5
0 0 1 0.5 0.5
3 1 0 6
50
60
70
80
90
100
0.5 0 0
0.5 0.5 0
0 0.5 0
0 0 0.5
0 0.5 0.5
0.5 0 0.5
$EndNodes
$Elements
2 2 1 2
2 1 2 1
1 10 20 30
3 1 11 1
2 10 20 30 40 50 60 70 80 90 100
$EndElements
EOF
cat > "$out/gmsh/hex20_v22.msh" <<'EOF'
$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
20
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
9 0.5 0 0
10 0 0.5 0
11 0 0 0.5
12 1 0.5 0
13 1 0 0.5
14 0.5 1 0
15 1 1 0.5
16 0 1 0.5
17 0.5 0 1
18 0 0.5 1
19 1 0.5 1
20 0.5 1 1
$EndNodes
$Elements
1
1 17 2 1 1 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20
$EndElements
EOF

# ---------------------------------------------------------------- TetGen (.node NUL .ele)
tetgen() { # name node-text ele-text
  { printf '%s' "$2"; printf '\0'; printf '%s' "$3"; } > "$out/tetgen/$1"
}
tetgen two_tets_1based $'5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n' \
  $'2 4 0\n1 1 2 3 4\n2 2 3 4 5\n'
tetgen one_tet_0based_attr $'# a comment\n4 3 2 1\n0 0 0 0 0.5 7 1\n1 1 0 0 0.5 7 0\n2 0 1 0 1 1 1\n3 0 0 1 1 1 0 # end\n' \
  $'1 4 1\n0 0 1 2 3 42\n'
tetgen commas $'4,3,0,0\n1,0,0,0\n2,2e0,0,0\n3,0,2,0\n4,0,0,2.5\n' $'1 4\n1 1 2 3 4\n'

# ---------------------------------------------------------------- scenes
cp "$root"/apps/scenes/*.json "$out/scene/"
cat > "$out/scene/small.json" <<'EOF'
{"version": 1, "name": "small",
 "background": {"element": "tet10", "box": {"min": [0, 0, 0], "max": [1.5, 0.5, 0.5]}, "cells": [3, 1, 1]},
 "geometry": {"shape": "box", "min": [0, 0, 0], "max": [1.2, 0.5, 0.5], "cells": [3, 1, 1]},
 "material": {"model": "snh", "young": 1e5, "poisson": 0.4, "density": 1000},
 "solver": {"method": "minres", "preconditioner": "schwarz", "rtol": 1e-8, "max_iterations": 2000},
 "time": {"dt": 0.02, "steps": 6},
 "effects": [{"gravity": {}}, {"damping": {"stiffness": 0.01, "mass": 0.1}},
  {"fixed": {"region": {"half_space": {"point": [0, 0, 0], "normal": [-1, 0, 0]}}}},
  {"motion": {"region": {"half_space": {"point": [1.5, 0, 0], "normal": [1, 0, 0]}},
   "velocity": [0, 0, 1], "end": 0.06, "release": true}},
  {"traction": {"region": {"box": {"min": [1.19, -1, -1], "max": [2, 1, 1]}}, "value": [1, 2, 3]}},
  {"pressure": {"region": {"half_space": {"point": [0, 0.49, 0], "normal": [0, 1, 0]}}, "value": 5}},
  {"initial_velocity": {"angular_velocity": [0, 0, 3]}}]}
EOF
echo '{"version": 1}' > "$out/scene/minimal.json"

# ---------------------------------------------------------------- surfaces (format byte + file)
surface() { # name format-byte(0 obj, 1 off, 2 stl, 3 ply) printf-format [args]
  local name=$1 fmt=$2
  shift 2
  { printf "\\$(printf '%03o' "$fmt")"; printf "$@"; } > "$out/surface/$name"
}
surface tet_obj 0 '# tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\ng a\nf 1 3 2\nf 1/1 2/1 4/1\nf 1//1 4//1 3//1\nf -3 -2 -1\n'
surface quad_obj 0 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl m\ns 1\nf 1 2 3 4\n'
surface tet_off 1 'OFF\n# tet\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n'
surface quad_off 1 'OFF 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n'
surface tri_stl 2 'solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nfacet normal 0 0 1\n outer loop\n  vertex 1 0 0\n  vertex 1 1 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n'
z4='\000\000\000\000' o4='\000\000\200\077' # float 0 and 1, little endian
surface tri_stl_bin 2 "solid binary%68s\001\000\000\000$z4$z4$o4$z4$z4$z4$o4$z4$z4$z4$o4$z4\000\000" ''
surface quad_ply 3 'ply\nformat ascii 1.0\ncomment q\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n4 0 1 2 3\n'
surface tri_ply_bin 3 "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n$z4$z4$z4$o4$z4$z4$z4$o4$z4\003$z4\001\000\000\000\002\000\000\000"

# ---------------------------------------------------------------- voxel images (format byte + file)
mkdir -p "$out/voxels"
voxels() { # name format-byte(0 nrrd, 1 mha) printf-format [args]
  name=$1 fmt=$2
  shift 2
  { printf "\\$(printf '%03o' "$fmt")"; printf "$@"; } > "$out/voxels/$name"
}
voxels raw_nrrd 0 'NRRD0004\n# c\ntype: uint16\ndimension: 3\nspace: 3D-right-handed\nsizes: 2 2 1\nspace directions: (1,0,0) (0,2,0) (0,0,1)\nspace origin: (0,0,0)\nendian: big\nencoding: raw\n\n\000\001\000\000\001\000\000\002'
voxels ascii_nrrd 0 'NRRD0001\ntype: float\ndimension: 3\nsizes: 2 2 2\nspacings: 0.5 0.5 0.5\nencoding: ascii\n\n1 0 1 1\n0.5 2 1 1\n'
voxels local_mha 1 'ObjectType = Image\nNDims = 3\nDimSize = 2 1 2\nElementSpacing = 1 1 2\nOffset = 1 2 3\nTransformMatrix = 0 1 0 1 0 0 0 0 1\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n\001\000\001\001'

# ---------------------------------------------------------------- checkpoints
"$build/fcm-fuzz-seed-checkpoint" "$out/checkpoint"
echo "make_corpus.sh: $(find "$out" -type f | wc -l) seeds in $out"
