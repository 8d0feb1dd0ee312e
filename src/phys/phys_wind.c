// SPDX-License-Identifier: MIT
// Wind for both engines: the velocity at a time (gusts or a series, vd_wind_at), and wind time
// series files: CSV rows t,vx,vy,vz (s, m/s), times not decreasing; a first line that is not
// numeric is a header, '#' starts a comment line (docs/formats.md). Errors name the line and
// column and say what was expected.
#include <errno.h>
#include <stdlib.h>

#include "phys_internal.h"

// one number of a row at s (leading blanks allowed): finite, and within +-lim; *end after it
static int row_number(const char* s, double lim, double* out, const char** end) {
  while (*s == ' ' || *s == '\t') s++;
  char* e;
  errno = 0;
  double v = strtod(s, &e);
  if (e == s || errno == ERANGE || !isfinite(v) || fabs(v) > lim) return 0;
  while (*e == ' ' || *e == '\t') e++;
  *out = v;
  *end = e;
  return 1;
}

vd_status vd_sim_parse_wind(const char* text, size_t len, const char* name, double** rows, int* n,
                            vd_error* err) {
  *rows = NULL;
  *n = 0;
  const char* file = name ? name : "";
  int cap = 0, cnt = 0, line = 0;
  double* r = NULL;
  vd_status st = VD_OK;
  size_t pos = 0;
  while (pos < len && !st) {
    // the line, without its end (at most 255 characters are read: longer is an error)
    line++;
    size_t e = pos;
    while (e < len && text[e] != '\n') e++;
    size_t ln = e - pos;
    char buf[256];
    const char* s = text + pos;
    const char* start = s;
    pos = e + 1;
    while (ln && (*s == ' ' || *s == '\t' || *s == '\r')) s++, ln--;
    while (ln && (s[ln - 1] == '\r' || s[ln - 1] == ' ' || s[ln - 1] == '\t')) ln--;
    if (!ln || *s == '#') continue;
    int c0 = (int)(s - start) + 1;  // column of buf[0]
    if (line == 1 && (*s < '0' || *s > '9') && *s != '-' && *s != '+' && *s != '.') continue;  // header
    if (ln >= sizeof buf) {
      st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0, "line longer than %d characters (expected 't,vx,vy,vz')",
                        (int)sizeof buf - 1);
      break;
    }
    memcpy(buf, s, ln);
    buf[ln] = 0;
    if (memchr(buf, 0, ln)) {
      st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0 + (int)((const char*)memchr(buf, 0, ln) - buf), "NUL byte (binary data, not CSV text)");
      break;
    }
    // t, vx, vy, vz
    double v[4];
    const char* p = buf;
    for (int k = 0; k < 4 && !st; k++) {
      const char* q;
      double lim = k == 0 ? 1e12 : VD_SIM_MAX_WIND;
      if (!row_number(p, lim, &v[k], &q))
        st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0 + (int)(p - buf),
                          k == 0 ? "expected a time t (s): a finite number within +-1e12"
                                 : "expected a wind velocity component (m/s): a finite number within +-%g",
                          VD_SIM_MAX_WIND);
      else if (k < 3 && *q != ',')
        st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0 + (int)(q - buf), "expected ',' (rows are t,vx,vy,vz)");
      else if (k == 3 && *q)
        st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0 + (int)(q - buf),
                          "expected the end of the row after vz (rows are t,vx,vy,vz)");
      else
        p = q + 1;
    }
    if (st) break;
    if (cnt && v[0] < r[4 * (cnt - 1)])
      st = vd_error_set(err, VD_ERR_FORMAT, file, line, c0, "time %g goes backwards (after %g)", v[0], r[4 * (cnt - 1)]);
    else if (cnt >= VD_SIM_MAX_WIND_ROWS)
      st = vd_error_set(err, VD_ERR_LIMIT, file, line, c0, "more than %d wind rows", VD_SIM_MAX_WIND_ROWS);
    else if (!vd_grow((void**)&r, &cap, cnt + 1, 4 * sizeof(double)))
      st = vd_error_set(err, VD_ERR_NOMEM, file, line, 0, "out of memory");
    else
      memcpy(r + 4 * cnt++, v, sizeof v);
  }
  if (!st && !cnt) st = vd_error_set(err, VD_ERR_FORMAT, file, 0, 0, "no wind rows (expected lines t,vx,vy,vz in s, m/s)");
  if (st) {
    vd_free(r, (size_t)cap * 4 * sizeof(double));
    return st;
  }
  // shrink to the exact size so the caller frees n rows
  double* x = vd_realloc(r, (size_t)cap * 4 * sizeof(double), (size_t)cnt * 4 * sizeof(double));
  if (!x) {
    vd_free(r, (size_t)cap * 4 * sizeof(double));
    return vd_error_set(err, VD_ERR_NOMEM, file, 0, 0, "out of memory");
  }
  *rows = x;
  *n = cnt;
  return VD_OK;
}

vd_status vd_sim_read_wind(const char* path, double** rows, int* n, vd_error* err) {
  *rows = NULL;
  *n = 0;
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_sim_parse_wind(text, len, path, rows, n, err);
  vd_free(text, len + 1);
  return st;
}

vd_vec3 vd_wind_at(vd_vec3 mean, double gust_amplitude, double gust_period, const double* series, int nseries,
                   double t) {
  // a time series replaces the mean wind and the gusts; linear between rows, held at the ends
  if (series && nseries > 0) {
    const double* w = series;
    if (t <= w[0] || nseries == 1) return vd_v3(w[1], w[2], w[3]);
    const double* z = w + 4 * (nseries - 1);
    if (t > z[0]) return vd_v3(z[1], z[2], z[3]);
    // the first row i with t <= t_i, by bisection (long series: no scan per step)
    int lo = 0, hi = nseries - 1;  // t > t_lo, t <= t_hi
    while (hi - lo > 1) {
      int mid = lo + (hi - lo) / 2;
      if (t <= w[4 * mid]) hi = mid;
      else lo = mid;
    }
    const double* a = w + 4 * (hi - 1);
    const double* b = w + 4 * hi;
    double s = b[0] > a[0] ? (t - a[0]) / (b[0] - a[0]) : 1.0;
    return vd_v3(a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2]), a[3] + s * (b[3] - a[3]));
  }
  double f = 1.0;
  if (gust_period > 0) f += gust_amplitude * sin(2 * VD_PI * t / gust_period);
  return vd_scale(mean, f);
}
