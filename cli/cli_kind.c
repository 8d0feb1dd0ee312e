// SPDX-License-Identifier: MIT
// What a file is, when it is given where a plant is expected and is not one: a mesh, a point
// cloud, an image, a run folder, JSON of another format. Told from the file's first bytes (and
// its name where the bytes say nothing), so `verdant grow tom.ply` says "tom.ply is a mesh"
// rather than reporting an L-Py syntax error in binary data.
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

// does the header text (up to end_header) declare faces?
static int ply_has_faces(const char* head) {
  const char* end = strstr(head, "end_header");
  const char* f = strstr(head, "element face ");
  return f && (!end || f < end) && f[13] != '0';
}

// the kind of JSON text by its "format"; NULL for plant and curves files
static const char* json_kind(const char* head, size_t n, char* buf, size_t cap) {
  char fmt[64];
  vd_plant_json_format(head, n, fmt, sizeof fmt);
  if (!strcmp(fmt, "verdant-plant") || !strcmp(fmt, "verdant-curves")) return NULL;
  if (!strcmp(fmt, "verdant-image")) return "an image sidecar (verdant-image JSON)";
  if (!strcmp(fmt, "verdant-dataset")) return "a dataset manifest (verdant-dataset JSON)";
  if (!strcmp(fmt, "verdant-render-run")) return "the index of a run's pictures (verdant-render-run JSON)";
  if (!strcmp(fmt, "verdant-rod")) return "the rod model of a simulation run (verdant-rod JSON)";
  if (fmt[0]) {
    snprintf(buf, cap, "JSON of another format (\"%s\")", fmt);
    return buf;
  }
  // without a "format" near the top: the plant reader says what it expected
  return NULL;
}

const char* cli_not_a_plant(const char* path, char* buf, size_t cap) {
  struct stat sb;
  if (stat(path, &sb) != 0) return NULL;  // the reader reports a missing file
  if (S_ISDIR(sb.st_mode)) {
    char rod[4200];
    snprintf(rod, sizeof rod, "%s/rod.json", path);
    return access(rod, 0) == 0 ? "a simulation run (its final plant is RUN/plant.json; 'verdant render RUN/' draws it)"
                               : "a folder";
  }
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  char head[4097];
  size_t n = fread(head, 1, sizeof head - 1, f);
  fclose(f);
  head[n] = 0;
  // binary and fixed signatures first
  if (n >= 4 && !memcmp(head, "LASF", 4)) return "a point cloud (LAS)";
  if (n >= 8 && !memcmp(head, "\x89PNG\r\n\x1a\n", 8)) return "an image (PNG)";
  if (n >= 4 && (!memcmp(head, "ply\n", 4) || !memcmp(head, "ply\r", 4)))
    return ply_has_faces(head) ? "a mesh (PLY)" : "a point cloud (PLY)";
  if (!strncmp(head, "# .PCD", 6) || !strncmp(head, "VERSION", 7)) return "a point cloud (PCD)";
  // text kinds
  const char* p = head;
  if (n >= 3 && !memcmp(p, "\xEF\xBB\xBF", 3)) p += 3;
  while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
  if (*p == '{') return json_kind(head, n, buf, cap);
  if (*p == '<') return strstr(head, "<mujoco") ? "a robot or scene (MuJoCo MJCF XML)" : "an XML file";
  // by name where the text alone is not telling (OBJ, XYZ and CSV are plain lines of numbers)
  if (cli_has_ext(path, ".obj")) return "a mesh (OBJ)";
  if (cli_has_ext(path, ".stl") || cli_has_ext(path, ".off")) return "a mesh";
  if (cli_has_ext(path, ".mtl")) return "a material library (MTL)";
  if (cli_has_ext(path, ".xyz") || cli_has_ext(path, ".csv") || cli_has_ext(path, ".pts"))
    return "a point cloud (XYZ/CSV) or a table";
  if (cli_has_ext(path, ".png") || cli_has_ext(path, ".jpg") || cli_has_ext(path, ".jpeg")) return "an image";
  if (cli_has_ext(path, ".mp4")) return "a video";
  return NULL;
}
