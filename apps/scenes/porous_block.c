/* Generator of porous_block.nrrd, the image of the example scene voxel_block.json: a
 * 24 x 16 x 12 voxel block (0.025 m voxels, 0.6 x 0.4 x 0.3 m) of value 1 with 16 spherical
 * pores of value 0 (centres and radii from a fixed linear congruential sequence), written
 * as an ascii NRRD. `porous_block OUT.nrrd` writes it; `porous_block --check FILE` exits 1
 * unless FILE is exactly what it would write (the test geom_porous_block_image). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NX = 24, NY = 16, NZ = 12, NPORES = 16 };

static unsigned long lcg(unsigned long *s)
{
  *s = (*s * 1103515245UL + 12345UL) & 0x7fffffffUL;
  return *s;
}

/* The file's bytes into buf (cap bytes); returns the length. */
static size_t generate(char *buf, size_t cap)
{
  double c[NPORES][3], r[NPORES];
  unsigned long s = 20261123UL;
  for (int p = 0; p < NPORES; p++) {
    c[p][0] = 2.0 + (double)(lcg(&s) % 200) / 200.0 * (NX - 4);
    c[p][1] = 2.0 + (double)(lcg(&s) % 200) / 200.0 * (NY - 4);
    c[p][2] = 3.0 + (double)(lcg(&s) % 200) / 200.0 * (NZ - 6);
    r[p] = 1.2 + (double)(lcg(&s) % 100) / 100.0 * 1.6;
  }
  size_t n = (size_t)snprintf(buf, cap,
                              "NRRD0004\n"
                              "# porous block for apps/scenes/voxel_block.json, written by "
                              "apps/scenes/porous_block.c\n"
                              "type: uint8\ndimension: 3\nspace: 3D-right-handed\n"
                              "sizes: %d %d %d\n"
                              "space directions: (0.025,0,0) (0,0.025,0) (0,0,0.025)\n"
                              "space origin: (0.0125,0.0125,0.0125)\n"
                              "encoding: ascii\n\n",
                              NX, NY, NZ);
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++) {
        int v = 1;
        for (int p = 0; p < NPORES; p++) {
          const double dx = i - c[p][0], dy = j - c[p][1], dz = k - c[p][2];
          if (dx * dx + dy * dy + dz * dz < r[p] * r[p]) v = 0;
        }
        if (n + 3 < cap) {
          buf[n++] = (char)('0' + v);
          buf[n++] = i == NX - 1 ? '\n' : ' ';
        }
      }
  return n;
}

int main(int argc, char **argv)
{
  static char want[65536], got[65536];
  const size_t n = generate(want, sizeof want);
  if (argc == 2) {
    FILE *f = fopen(argv[1], "wb");
    if (!f || fwrite(want, 1, n, f) != n || fclose(f) != 0) {
      fprintf(stderr, "porous_block: cannot write %s\n", argv[1]);
      return 1;
    }
    return 0;
  }
  if (argc == 3 && strcmp(argv[1], "--check") == 0) {
    FILE *f = fopen(argv[2], "rb");
    size_t m = f ? fread(got, 1, sizeof got, f) : 0;
    if (f) fclose(f);
    if (m != n || memcmp(got, want, n) != 0) {
      fprintf(stderr, "porous_block: %s differs from the generated image (%zu vs %zu bytes)\n",
              argv[2], m, n);
      return 1;
    }
    return 0;
  }
  fprintf(stderr, "usage: porous_block OUT.nrrd | porous_block --check FILE\n");
  return 2;
}
