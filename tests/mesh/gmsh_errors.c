/* fcm_mesh_create_from_gmsh on bad input: a missing file (FCM_ERR_IO), malformed files
 * (FCM_ERR_FORMAT naming file:line and what was expected), and files it does not support
 * (binary, other or mixed volume types, no volume elements: FCM_ERR_UNSUPPORTED). */
#include "mesh_util.h"

#define PATH   "mesh_gmsh_errors.msh"
#define HEAD41 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
#define HEAD22 "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
/* One unit tet, tags 1..4, in both versions (lines 4-10 of the files are $Nodes). */
#define NODES41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
#define NODES22 "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"

static void expect(fcm_ctx *ctx, const char *text, fcm_status code, const char *substr, int line)
{
  char where[64];
  fcm_mesh *m = (fcm_mesh *)&where; /* must be reset to NULL */
  TEST_TRUE(write_text(PATH, text) == 0);
  fcm_status st = fcm_mesh_create_from_gmsh(ctx, PATH, &m);
  const char *msg = fcm_ctx_error_message(ctx);
  if (st != code)
    TEST_FAIL_("status %s, expected %s; message: %s; file:\n%s", fcm_status_name(st),
               fcm_status_name(code), msg, text);
  if (!strstr(msg, substr)) TEST_FAIL_("message \"%s\" lacks \"%s\"", msg, substr);
  if (line > 0) {
    snprintf(where, sizeof where, PATH ":%d: ", line);
    if (!strstr(msg, where)) TEST_FAIL_("message \"%s\" lacks \"%s\"", msg, where);
  }
  TEST_TRUE(m == NULL);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_error_clear(ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  fcm_mesh *m = NULL;

  /* The reference files are valid. */
  TEST_TRUE(write_text(PATH, HEAD41 NODES41
                       "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n") == 0);
  TEST_OK(ctx, fcm_mesh_create_from_gmsh(ctx, PATH, &m));
  TEST_TRUE(m && fcm_mesh_num_cells(m) == 1 && fcm_mesh_num_nodes(m) == 4);
  fcm_mesh_destroy(&m);
  TEST_TRUE(write_text(PATH, HEAD22 NODES22 "$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n") ==
            0);
  TEST_OK(ctx, fcm_mesh_create_from_gmsh(ctx, PATH, &m));
  TEST_TRUE(m && fcm_mesh_num_cells(m) == 1);
  fcm_mesh_destroy(&m);

  /* Missing file. */
  TEST_ERR(ctx, fcm_mesh_create_from_gmsh(ctx, "no/such/dir/mesh.msh", &m), FCM_ERR_IO,
           "Gmsh file: cannot open 'no/such/dir/mesh.msh'");
  TEST_TRUE(m == NULL);
  TEST_ERR(ctx, fcm_mesh_create_from_gmsh(ctx, NULL, &m), FCM_ERR_ARG, "must not be NULL");

  /* Header problems. */
  expect(ctx, "", FCM_ERR_FORMAT, "unexpected end of file; expected $MeshFormat", 1);
  expect(ctx, "$Nodes\n", FCM_ERR_FORMAT, "expected $MeshFormat, found '$Nodes'", 1);
  expect(ctx, "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", FCM_ERR_FORMAT, "unknown MSH version '3.0'",
         2);
  expect(ctx, "$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", FCM_ERR_FORMAT, "unknown MSH version '4.0'",
         2);
  expect(ctx, "$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n", FCM_ERR_UNSUPPORTED,
         "binary MSH files are not supported", 2);
  expect(ctx, "$MeshFormat\n4.1 0\n$EndMeshFormat\n", FCM_ERR_FORMAT,
         "expected data size (an integer), found '$EndMeshFormat'", 3);
  expect(ctx, HEAD41 "junk\n", FCM_ERR_FORMAT, "expected a section header ($Name), found 'junk'",
         4);
  expect(ctx, HEAD41 "$Comments\nno end\n", FCM_ERR_FORMAT,
         "expected $EndComments to close the section opened at line 4", 0);

  /* Truncated files. */
  expect(ctx, HEAD41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0", FCM_ERR_FORMAT,
         "unexpected end of file; expected node z coordinate", 12);
  expect(ctx, HEAD22 NODES22 "$Elements\n1\n1 4 2 1 1 1 2 3", FCM_ERR_FORMAT,
         "unexpected end of file; expected element node tag", 13);
  expect(ctx, HEAD22 NODES22, FCM_ERR_FORMAT, "no $Elements section", 0);

  /* Bad counts. */
  expect(ctx, HEAD22 "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "expected node tag (an integer), found '$EndNodes'", 10);
  expect(ctx, HEAD22 "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "expected $EndNodes, found '4'", 9);
  expect(ctx,
         HEAD41 "$Nodes\n1 5 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n",
         FCM_ERR_FORMAT, "the $Nodes header announces 5 nodes but its blocks hold 4", 0);
  expect(ctx, HEAD41 "$Nodes\n1 3 1 4\n3 1 0 4\n", FCM_ERR_FORMAT,
         "number of nodes in block = 4 out of range [0, 3]", 6);
  expect(ctx, HEAD22 NODES22 "$Elements\n2\n1 4 2 1 1 1 2 3 4\n$EndElements\n", FCM_ERR_FORMAT,
         "expected element tag (an integer), found '$EndElements'", 14);
  expect(ctx, HEAD41 NODES41 "$Elements\n1 2 1 2\n3 1 4 2\n1 1 2 3 4\n$EndElements\n",
         FCM_ERR_FORMAT, "expected element tag (an integer), found '$EndElements'", 20);
  expect(ctx, HEAD22 "$Nodes\n99999999\n1 0 0 0\n$EndNodes\n", FCM_ERR_FORMAT,
         "number of nodes = 99999999 out of range", 5);

  /* Wrong numbers. */
  expect(ctx, HEAD22 "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1.0.0 0\n4 0 0 1\n$EndNodes\n",
         FCM_ERR_FORMAT, "expected node y coordinate (a finite number), found '1.0.0'", 8);
  expect(ctx, HEAD22 "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 nan 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "expected node y coordinate (a finite number), found 'nan'", 8);
  expect(ctx, HEAD22 "$Nodes\n4\n1 0 0 0\n2.5 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "expected node tag (an integer), found '2.5'", 7);
  expect(ctx, HEAD22 "$Nodes\n4\n1 0 0 0\n0 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "node tag = 0 out of range [1,", 7);
  expect(ctx, HEAD22 "$Nodes\n4\n1 0 0 0\n2 1 0 0\n1 0 1 0\n4 0 0 1\n$EndNodes\n", FCM_ERR_FORMAT,
         "node tag 1 appears twice", 8);
  expect(ctx,
         HEAD41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n7\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n",
         FCM_ERR_FORMAT, "node tag = 7 out of range [1, 4]", 9);
  expect(ctx, HEAD22 NODES22 "$Elements\n1\n1 4 2 1 1 1 2 3 9\n$EndElements\n", FCM_ERR_FORMAT,
         "element node tag 9 is not defined in $Nodes", 13);
  expect(ctx, HEAD22 "$Elements\n0\n$EndElements\n", FCM_ERR_FORMAT, "$Elements before $Nodes", 4);

  /* Valid files the reader does not support. */
  expect(ctx, HEAD41 NODES41 "$Elements\n1 1 1 1\n3 1 6 1\n1 1 2 3 4 1 2\n$EndElements\n",
         FCM_ERR_UNSUPPORTED, "volume element type 6 is not supported", 18);
  expect(ctx, HEAD22 NODES22 "$Elements\n1\n1 7 2 1 1 1 2 3 4 1\n$EndElements\n",
         FCM_ERR_UNSUPPORTED, "volume element type 7 is not supported", 13);
  expect(ctx,
         HEAD22 "$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0 0 1\n6 1 0 1\n7 1 1 1\n"
                "8 0 1 1\n$EndNodes\n$Elements\n2\n1 5 0 1 2 3 4 5 6 7 8\n2 4 0 1 2 4 5\n"
                "$EndElements\n",
         FCM_ERR_UNSUPPORTED, "volume element of Gmsh type 4 after elements of type 5", 18);
  expect(ctx, HEAD22 NODES22 "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n", FCM_ERR_UNSUPPORTED,
         "no volume elements", 0);

  remove(PATH);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
