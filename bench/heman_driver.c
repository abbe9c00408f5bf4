/* bench/heman_driver.c: times heman's ambient occlusion (heman_lighting_compute_occlusion,
 * github.com/prideout/heman: 16 lattice-direction hull-stack sweeps, OpenMP) on a height field,
 * for bench/heman_compare.sh. Our code; it links against a heman the user built (heman itself is
 * not part of this repository).
 *
 *   heman_driver IN.raw WIDTH HEIGHT [--reps N] [--warmup N] [--scale S] [--out OUT.raw]
 *   heman_driver --probe
 *
 * IN.raw: WIDTH x HEIGHT little-endian float32 heights, row-major, row 0 first.
 * --scale S: heman_lighting_set_occlusion_scale(S). heman places cell (i, j) at
 *   (i, j) * S / max(WIDTH, HEIGHT); the default S = max(WIDTH, HEIGHT) makes cells 1 unit wide,
 *   the geometry hfvis uses for a field in pixel units (cell size 1).
 * --out OUT.raw: the last run's occlusion image (1 = unoccluded), little-endian float32.
 * Prints, one "key=value" per line: threads, read_seconds, then compute_seconds per timed run
 * (wall clock, CLOCK_MONOTONIC, around heman_lighting_compute_occlusion including its
 * allocations), write_seconds and mean_ao. --probe prints the size of heman's HEMAN_FLOAT as the
 * library was built and as this driver was compiled (they must match; see the script).
 */
#define _POSIX_C_SOURCE 199309L
#include <heman.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static double now_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void die(const char* message, const char* detail) {
  fprintf(stderr, "heman_driver: %s%s%s\n", message, detail ? ": " : "", detail ? detail : "");
  exit(1);
}

static int host_is_little_endian(void) {
  const uint32_t one = 1;
  unsigned char first;
  memcpy(&first, &one, 1);
  return first == 1;
}

static long parse_long(const char* text, const char* what, long min) {
  char* end = NULL;
  const long value = strtol(text, &end, 10);
  if (!end || *end || value < min) die("invalid value for", what);
  return value;
}

/* sizeof(HEMAN_FLOAT) as libheman.a was compiled: heman_image_texel does its pointer arithmetic
 * in the library's type. */
static int library_float_bytes(void) {
  heman_image* image = heman_image_create(2, 1, 1);
  const int bytes = (int)((char*)heman_image_texel(image, 1, 0) - (char*)heman_image_data(image));
  heman_image_destroy(image);
  return bytes;
}

int main(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "--probe") == 0) {
    printf("library_float_bytes=%d\ndriver_float_bytes=%d\n", library_float_bytes(),
           (int)sizeof(HEMAN_FLOAT));
    return 0;
  }
  if (argc < 4) {
    fprintf(stderr,
            "usage: heman_driver IN.raw WIDTH HEIGHT [--reps N] [--warmup N] [--scale S] "
            "[--out OUT.raw]\n       heman_driver --probe\n");
    return 2;
  }
  if (!host_is_little_endian()) die("this driver reads little-endian float32 and needs a little-endian host", NULL);
  if (library_float_bytes() != (int)sizeof(HEMAN_FLOAT)) {
    fprintf(stderr,
            "heman_driver: libheman.a uses %d-byte HEMAN_FLOAT but this driver was compiled for %d "
            "bytes (USE_DOUBLE_PRECISION must match)\n",
            library_float_bytes(), (int)sizeof(HEMAN_FLOAT));
    return 1;
  }
  const char* input = argv[1];
  const long width = parse_long(argv[2], "WIDTH", 1);
  const long height = parse_long(argv[3], "HEIGHT", 1);
  long reps = 1, warmup = 0;
  double scale = (double)(width > height ? width : height);
  const char* output = NULL;
  for (int i = 4; i < argc; ++i) {
    if (i + 1 >= argc) die("missing value after", argv[i]);
    if (strcmp(argv[i], "--reps") == 0) {
      reps = parse_long(argv[++i], "--reps", 1);
    } else if (strcmp(argv[i], "--warmup") == 0) {
      warmup = parse_long(argv[++i], "--warmup", 0);
    } else if (strcmp(argv[i], "--scale") == 0) {
      scale = atof(argv[++i]);
      if (!(scale > 0)) die("--scale must be > 0", NULL);
    } else if (strcmp(argv[i], "--out") == 0) {
      output = argv[++i];
    } else {
      die("unknown argument", argv[i]);
    }
  }
  const size_t count = (size_t)width * (size_t)height;

#ifdef _OPENMP
  printf("threads=%d\n", omp_get_max_threads());
#else
  printf("threads=1\n");
#endif

  /* Read the heights (part of the process's work, reported separately). */
  const double read_start = now_seconds();
  FILE* in = fopen(input, "rb");
  if (!in) die("cannot open", input);
  float* heights = malloc(count * sizeof(float));
  if (!heights) die("out of memory", NULL);
  if (fread(heights, sizeof(float), count, in) != count) die("short read (wrong WIDTH/HEIGHT?)", input);
  if (fgetc(in) != EOF) die("file is longer than WIDTH x HEIGHT float32 values", input);
  fclose(in);
  heman_image* field = heman_image_create((int)width, (int)height, 1);
  HEMAN_FLOAT* data = heman_image_data(field);
  for (size_t i = 0; i < count; ++i) data[i] = (HEMAN_FLOAT)heights[i];
  free(heights);
  printf("read_seconds=%.6f\n", now_seconds() - read_start);

  heman_lighting_set_occlusion_scale((float)scale);
  heman_image* occlusion = NULL;
  for (long run = 0; run < warmup + reps; ++run) {
    if (occlusion) heman_image_destroy(occlusion);
    const double start = now_seconds();
    occlusion = heman_lighting_compute_occlusion(field);
    const double seconds = now_seconds() - start;
    if (run >= warmup) printf("compute_seconds=%.6f\n", seconds);
    fflush(stdout);
  }

  const HEMAN_FLOAT* ao = heman_image_data(occlusion);
  double sum = 0;
  for (size_t i = 0; i < count; ++i) sum += ao[i];
  if (output) {
    const double write_start = now_seconds();
    float* values = malloc(count * sizeof(float));
    if (!values) die("out of memory", NULL);
    for (size_t i = 0; i < count; ++i) values[i] = (float)ao[i];
    FILE* out = fopen(output, "wb");
    if (!out) die("cannot write", output);
    if (fwrite(values, sizeof(float), count, out) != count || fclose(out) != 0) die("write failed", output);
    free(values);
    printf("write_seconds=%.6f\n", now_seconds() - write_start);
  }
  printf("mean_ao=%.6f\n", sum / (double)count);
  heman_image_destroy(occlusion);
  heman_image_destroy(field);
  return 0;
}
