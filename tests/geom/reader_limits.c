/* Readers against hostile inputs (counts in headers, non-regular files): counts in a header
 * are bounded by the size of the file before anything is allocated for them (unchecked, a
 * 14-byte TetGen .node file asks for 2.4 TB, a 23-byte one for 709 MB; a Gmsh $Nodes
 * count likewise), and directories, character devices (/dev/zero) and pipes are refused
 * with FCM_ERR_IO naming the file, for the TetGen, Gmsh and scene readers, before any
 * read. The allocator records the largest request and refuses anything above 64 MiB, so
 * an unbounded reader fails this test quickly instead of exhausting the machine. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/geom.h"
#include "fcm/mesh.h"
#include "fcm/scene.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

enum { CAP = 64 << 20 };

static size_t largest; /* largest request since the last reset */

static void *capped_alloc(void *user, size_t size)
{
  (void)user;
  if (size > largest) largest = size;
  return size > CAP ? NULL : malloc(size);
}

static void capped_release(void *user, void *p)
{
  (void)user;
  free(p);
}

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

int main(void)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = capped_alloc;
  o.allocator.release = capped_release;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) return 1;
  alarm(60); /* a reader blocking on the pipe below fails the test instead of hanging it */
  fcm_geometry *g = NULL;
  fcm_mesh *m = NULL;
  fcm_scene *s = NULL;
  write_file("rl_ok.ele", "1 4\n1 1 2 3 4\n");

  /* header counts beyond what the file can hold; no allocation above a few KiB. */
  write_file("rl_14.node", "99999999999 3\n"); /* 14 bytes: 2.4 TB of coordinates */
  largest = 0;
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "rl_14.node", "rl_ok.ele", &g), FCM_ERR_FORMAT,
           "rl_14.node:1: number of points");
  TEST_TRUE(largest < 4096 && g == NULL);
  write_file("rl_23.node", "29500000 3\n0 0 0 0\n1 0\n"); /* 23 bytes: 709 MB before */
  largest = 0;
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "rl_23.node", "rl_ok.ele", &g), FCM_ERR_FORMAT,
           "outside [0, 3]");
  TEST_TRUE(largest < 4096 && g == NULL);
  write_file("rl_4.node", "4 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  write_file("rl_big.ele", "9999999999 4\n1 1 2 3 4\n");
  largest = 0;
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "rl_4.node", "rl_big.ele", &g), FCM_ERR_FORMAT,
           "rl_big.ele:1: number of tetrahedra");
  TEST_TRUE(largest < 4096 && g == NULL);
  /* the bound admits the smallest valid files */
  write_file("rl_min.node", "4 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1");
  write_file("rl_min.ele", "1 4\n1 1 2 3 4");
  TEST_OK(ctx, fcm_geometry_create_from_tetgen(ctx, "rl_min.node", "rl_min.ele", &g));
  TEST_TRUE(g && fcm_geometry_num_cells(g) == 1);
  fcm_geometry_destroy(&g);

  /* Gmsh: a $Nodes count of 10^8 in a file of 120 bytes (8 bytes per node at least). */
  write_file("rl_nodes.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n100000000\n"
                             "1 0 0 0\n$EndNodes\n$Elements\n0\n$EndElements\n");
  largest = 0;
  TEST_ERR(ctx, fcm_mesh_create_from_gmsh(ctx, "rl_nodes.msh", &m), FCM_ERR_FORMAT,
           "number of nodes");
  TEST_TRUE(largest < (1 << 16) + 4096 && m == NULL);

  /* Non-regular files: refused by name, nothing read. */
  const char *dev = "/dev/zero";
  struct stat sb;
  TEST_TRUE(mkdir("rl_dir", 0700) == 0 || stat("rl_dir", &sb) == 0);
  remove("rl_fifo");
  int have_fifo = mkfifo("rl_fifo", 0600) == 0;
  const char *bad[3] = {dev, "rl_dir", have_fifo ? "rl_fifo" : dev};
  for (int k = 0; k < 3; k++) {
    char expect[64];
    snprintf(expect, sizeof expect, "'%s' is not a regular file", bad[k]);
    largest = 0;
    TEST_ERR(ctx, fcm_mesh_create_from_gmsh(ctx, bad[k], &m), FCM_ERR_IO, expect);
    TEST_ERR(ctx, fcm_geometry_create_from_gmsh(ctx, bad[k], &g), FCM_ERR_IO, expect);
    TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, bad[k], "rl_ok.ele", &g), FCM_ERR_IO,
             expect);
    TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "rl_4.node", bad[k], &g), FCM_ERR_IO,
             expect);
    TEST_ERR(ctx, fcm_scene_create_from_file(ctx, bad[k], &s), FCM_ERR_IO, expect);
    TEST_TRUE(largest < 4096 && m == NULL && g == NULL && s == NULL);
  }
  TEST_TRUE(have_fifo);
  remove("rl_fifo");
  rmdir("rl_dir");
  const char *files[] = {"rl_ok.ele",  "rl_14.node",  "rl_23.node", "rl_4.node",
                         "rl_big.ele", "rl_min.node", "rl_min.ele", "rl_nodes.msh"};
  for (size_t k = 0; k < sizeof files / sizeof files[0]; k++)
    remove(files[k]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
