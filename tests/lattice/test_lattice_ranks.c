/* The blocks of the lattice over ranks (px_lattice_ranks_split,
 * lattice_ranks.c): boundaries balance the elements, every block keeps at
 * least its minimum width (a plane; rows: a plane's rows), and impossible
 * splits are refused; the (y, z) rank grid chosen from the extents
 * (px_lattice_ranks_grid) has the least halo area. The runs themselves
 * on 1..4 ranks are compared file by file in tests/cli (test_mpi_lattice_*). */
#include <stdlib.h>

#include "px_test.h"
#include "solvers/lattice/lattice.h"

/* split count[0..nz) over size slabs and compare with want[0..size] */
static void check_split(const size_t *count, long nz, int size, const long *want) {
  long z[8];
  int r, same = 1;
  PX_CHECK(px_lattice_ranks_split(count, nz, 1, size, z) == 0);
  for (r = 0; r <= size; ++r) same &= z[r] == want[r];
  PX_CHECK_MSG(same, "split of %ld planes over %d: got %ld %ld %ld ... %ld", nz, size, z[0], z[1],
               size > 1 ? z[2] : -1L, z[size]);
}

static void test_examples(void) {
  static const size_t uniform[4] = {10, 10, 10, 10}, heavy[5] = {100, 1, 1, 1, 1};
  static const size_t top[4] = {0, 0, 0, 100}, bottom[4] = {100, 0, 0, 0};
  static const long u1[2] = {0, 4}, u2[3] = {0, 2, 4}, u3[4] = {0, 2, 3, 4},
                    u4[5] = {0, 1, 2, 3, 4};
  static const long h2[3] = {0, 1, 5}, t3[4] = {0, 2, 3, 4}, b3[4] = {0, 1, 2, 4};
  long z[8];
  check_split(uniform, 4, 1, u1);
  check_split(uniform, 4, 2, u2);
  /* 1/3 and 2/3 of 40 elements are reached at planes 2 (20) and 3 (30) */
  check_split(uniform, 4, 3, u3);
  check_split(uniform, 4, 4, u4);
  /* the heavy first plane alone holds half */
  check_split(heavy, 5, 2, h2);
  /* all elements in the last plane: the boundaries stop where the slabs
   * above still get a plane each */
  check_split(top, 4, 3, t3);
  /* all in the first: the slabs above take one plane each, the last the rest */
  check_split(bottom, 4, 3, b3);
  PX_CHECK(px_lattice_ranks_split(uniform, 4, 1, 5, z) == -1);
  PX_CHECK(px_lattice_ranks_split(uniform, 4, 1, 0, z) == -1);
}

/* Random bodies: boundaries strictly increasing from 0 to nz, and each
 * unclamped boundary the first plane where the elements below reach r/size. */
static void test_random(void) {
  size_t count[64];
  long z[9];
  int t;
  srand(21);
  for (t = 0; t < 2000; ++t) {
    long nz = 1 + rand() % 64, k;
    int size = 1 + rand() % 8, r, ok = 1;
    size_t total = 0;
    for (k = 0; k < nz; ++k) total += count[k] = (size_t)(rand() % 4 == 0 ? 0 : rand() % 1000);
    if (nz < size) {
      PX_CHECK(px_lattice_ranks_split(count, nz, 1, size, z) == -1);
      continue;
    }
    PX_CHECK(px_lattice_ranks_split(count, nz, 1, size, z) == 0);
    ok &= z[0] == 0 && z[size] == nz;
    for (r = 1; r <= size; ++r) ok &= z[r] > z[r - 1];
    for (r = 1; r < size; ++r) {
      size_t below = 0, last;
      for (k = 0; k < z[r]; ++k) below += count[k];
      last = z[r] > 0 ? below - count[z[r] - 1] : 0;
      /* clamped from below (z[r - 1] + 1) or above (nz - (size - r)), or
       * the first plane that reaches the share */
      if (z[r] != z[r - 1] + 1 && z[r] != nz - (size - r))
        ok &= below * (size_t)size >= total * (size_t)r && last * (size_t)size < total * (size_t)r;
    }
    PX_CHECK_MSG(ok, "random split %d: %ld planes over %d ranks", t, nz, size);
  }
}

/* Blocks of grid rows (the gather scheme): a plate of 5 planes of 50 rows
 * of 100 elements, which whole planes split 15000 / 10000 over 2 ranks and
 * 10000 / 5000 / 5000 / 5000 over 4, splits evenly by rows; every block
 * keeps at least minw = 50 rows (its halo reaches a plane's rows away), and
 * too many ranks for that are refused. */
static void test_rows(void) {
  static size_t plate[250];
  static const long w2[3] = {0, 125, 250}, w4[5] = {0, 63, 125, 188, 250};
  /* 3 planes of 2 rows, all the elements in the first row: the blocks of at
   * least 2 rows take the first 2, then 2 each */
  static const size_t first[6] = {60, 0, 0, 0, 0, 0};
  static const long f3[4] = {0, 2, 4, 6};
  long z[8];
  int r, ok;
  for (r = 0; r < 250; ++r) plate[r] = 100;
  PX_CHECK(px_lattice_ranks_split(plate, 250, 50, 2, z) == 0);
  for (ok = 1, r = 0; r <= 2; ++r) ok &= z[r] == w2[r];
  PX_CHECK_MSG(ok, "plate rows over 2: %ld %ld %ld", z[0], z[1], z[2]);
  PX_CHECK(px_lattice_ranks_split(plate, 250, 50, 4, z) == 0);
  for (ok = 1, r = 0; r <= 4; ++r) ok &= z[r] == w4[r];
  PX_CHECK_MSG(ok, "plate rows over 4: %ld %ld %ld %ld %ld", z[0], z[1], z[2], z[3], z[4]);
  PX_CHECK(px_lattice_ranks_split(plate, 250, 50, 5, z) == 0);
  for (ok = 1, r = 1; r <= 5; ++r) ok &= z[r] - z[r - 1] >= 50;
  PX_CHECK_MSG(ok, "plate rows over 5: blocks of 50 rows or more");
  PX_CHECK(px_lattice_ranks_split(plate, 250, 50, 6, z) == -1);
  PX_CHECK(px_lattice_ranks_split(first, 6, 2, 3, z) == 0);
  for (ok = 1, r = 0; r <= 3; ++r) ok &= z[r] == f3[r];
  PX_CHECK_MSG(ok, "first-row split: %ld %ld %ld %ld", z[0], z[1], z[2], z[3]);
  PX_CHECK(px_lattice_ranks_split(first, 6, 0, 2, z) == -1);
}

/* The rank grid of extents n over size ranks is py x pz (0 0: none). */
static void check_grid(int n0, int n1, int n2, int size, int py, int pz) {
  const int n[3] = {n0, n1, n2};
  int gy = 0, gz = 0, rc = px_lattice_ranks_grid(n, size, &gy, &gz);
  if (py == 0)
    PX_CHECK_MSG(rc == -1, "%d x %d x %d over %d: %d x %d, none expected", n0, n1, n2, size, gy,
                 gz);
  else
    PX_CHECK_MSG(rc == 0 && gy == py && gz == pz, "%d x %d x %d over %d: %d x %d, %d x %d expected",
                 n0, n1, n2, size, gy, gz, py, pz);
}

/* Hand-counted halo areas in cut faces per x cell, (pz - 1) n[1] +
 * (py - 1) n[2]: */
static void test_grid(void) {
  /* the plate 100 x 50 x 5: a y cut crosses 5 faces, a z cut 50:
   * 2 ranks 2 x 1 (5, against 50); 4 ranks 4 x 1 (15; 2 x 2: 55; 1 x 4: 150) */
  check_grid(100, 50, 5, 2, 2, 1);
  check_grid(100, 50, 5, 4, 4, 1);
  /* a plate 2 thick: 3 ranks 3 x 1 (4; 1 x 3 does not fit) */
  check_grid(40, 20, 2, 3, 3, 1);
  /* a square (y, z) section 8 x 8: 4 ranks 2 x 2 (16; 4 x 1 and 1 x 4: 24);
   * 2 and 3 ranks tie (8 and 8, 16 and 16): the fewer z cuts */
  check_grid(4, 8, 8, 4, 2, 2);
  check_grid(4, 8, 8, 2, 2, 1);
  check_grid(4, 8, 8, 3, 3, 1);
  /* a bar along z 4 x 4 x 13: z cuts are the small ones (1 x 2: 4;
   * 1 x 4: 12, 2 x 2: 17, 4 x 1: 39) */
  check_grid(4, 4, 13, 2, 1, 2);
  check_grid(4, 4, 13, 4, 1, 4);
  /* 6 ranks on 10 x 6 x 9: 2 x 3 (2 x 6 + 1 x 9 = 21; 3 x 2: 24, 1 x 6: 30,
   * 6 x 1: 45) */
  check_grid(10, 6, 9, 6, 2, 3);
  /* a block at least one cell wide: 4 x 1 needs 4 y cells (n[1] = 3): 1 x 4
   * (9) and 2 x 2 (43) remain */
  check_grid(10, 3, 40, 4, 1, 4);
  /* one rank; none fits: 5 ranks (prime) or 8 on a 2 x 2 section, 0 ranks */
  check_grid(3, 3, 3, 1, 1, 1);
  check_grid(5, 2, 2, 4, 2, 2);
  check_grid(5, 2, 2, 5, 0, 0);
  check_grid(5, 2, 2, 8, 0, 0);
  check_grid(5, 2, 2, 0, 0, 0);
}

int main(void) {
  test_examples();
  test_grid();
  test_rows();
  test_random();
  return px_test_report("test_lattice_ranks");
}
