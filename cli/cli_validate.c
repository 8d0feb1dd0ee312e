// SPDX-License-Identifier: MIT
// verdant validate: the physics against analytic references (docs/validation.md).
#include <cjson/cJSON.h>
#include <string.h>

#include "cli.h"

static const char* validate_help =
    "usage: verdant validate [--json] [--full] [--case TEXT] [--plant PLANT]\n"
    "\n"
    "Run the rod physics against analytic references: cantilevers under tip load, self-weight\n"
    "and end moment (to a full circle), shear, torsion, large deflection, first frequency (with\n"
    "a fruit), buckling, fracture, contacts, and independence of iterations, time step and\n"
    "discretisation; each in the discrete model's exact form and in continuum form. Then the\n"
    "harvest cases: detachment forces per site against the tomato literature, bend against\n"
    "pull, Gazebo Plants' bending and C_s^max runs, two-way coupling against the rod's force.\n"
    "Exit code 0 when every check passes, 1 when one fails.\n"
    "\n"
    "options:\n"
    "      --json          print a JSON list of {name, form, quantity, measured, reference,\n"
    "                      error, tolerance, pass, note} instead of the table\n"
    "      --full          the full sweep: finer rods, Greenhill column, Gazebo Plants figures 6-7\n"
    "      --case TEXT     run only the cases whose name contains TEXT\n"
    "      --plant PLANT   also check sag-free initialisation on this plant (.lpy or .json)\n";

static void progress(void* user, const char* name) {
  (void)user;
  fprintf(stderr, "\rvalidating %-40s", name);
  fflush(stderr);
}

int cli_validate(int argc, char** argv) {
  // validate writes no outputs: its scratch files (a robot, an exported beam) live in private
  // mkdtemp folders that the library removes before it returns, so no output layer is asked
  vd_outfile_set_guard(NULL);
  int json = 0, full = 0;
  const char* filter = NULL;
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      fputs(validate_help, stdout);
      return EXIT_OK;
    }
    if (!strcmp(a, "--json")) {
      json = 1;
    } else if (!strcmp(a, "--full")) {
      full = 1;
    } else if (!strcmp(a, "--case")) {
      if (i + 1 >= argc) return cli_usage_error("validate", "--case needs a value");
      filter = argv[++i];
    } else if (!strcmp(a, "--plant")) {
      if (i + 1 >= argc) return cli_usage_error("validate", "--plant needs a file");
      po.path = argv[++i];
    } else if (!strcmp(a, "--no-progress")) {
      po.progress = 0;
    } else {
      return cli_usage_error("validate", "unknown argument '%s'", a);
    }
  }
  vd_error err = {0};
  vd_plant_spec* spec = NULL;
  vd_model* plant = NULL;
  vd_status st = VD_OK;
  if (po.path) {
    cli_grow_info info;
    int prog = po.progress;
    po.progress = 0;
    st = cli_load_plant(&po, &spec, &info, &err);
    po.progress = prog;
    if (!st) cli_grow_info_free(&info);
    if (!st) st = vd_plant_compile(spec, &plant, &err);
    cli_blame_input(&err, po.path);
    if (st) {
      vd_plant_spec_destroy(spec);
      return cli_report("validate", &err, st);
    }
  }
  vd_validate_def def;
  memset(&def, 0, sizeof def);
  def.full = full;
  def.filter = filter;
  def.plant = plant;
  if (po.progress) def.progress = progress;
  vd_validate_result* r = NULL;
  int n = 0;
  double t0 = cli_now();
  st = vd_sim_validate(&def, &r, &n, &err);
  // the mass-spring trees, growth runs, harvest cases and the flexible export in MuJoCo
  // (docs/validation.md) after the rods
  for (int part = 0; part < 4 && !st; part++) {
    vd_validate_result* r2 = NULL;
    int n2 = 0;
    st = part == 0   ? vd_mss_validate(&def, &r2, &n2, &err)
         : part == 1 ? vd_growth_validate(&def, &r2, &n2, &err)
         : part == 2 ? vd_robot_validate(&def, &r2, &n2, &err)
                     : vd_robot_validate_export(&def, &r2, &n2, &err);
    if (!st && n2) {
      vd_validate_result* all = vd_realloc(r, sizeof *r * (size_t)n, sizeof *r * (size_t)(n + n2));
      if (!all) {
        st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      } else {
        memcpy(all + n, r2, sizeof *r2 * (size_t)n2);
        r = all;
        n += n2;
      }
    }
    vd_free(r2, sizeof *r2 * (size_t)n2);
  }
  if (po.progress) fprintf(stderr, "\r%60s\r", "");
  vd_model_destroy(plant);
  vd_plant_spec_destroy(spec);
  if (st) {
    vd_free(r, sizeof *r * (size_t)n);
    cli_report("validate", &err, st);
    return EXIT_FAIL;
  }
  // a filter that matches nothing is a usage error, not a pass
  if (n == 0) {
    vd_free(r, 0);
    return cli_usage_error("validate", "--case '%s' matches no validation case", filter ? filter : "");
  }
  int fails = 0;
  for (int k = 0; k < n; k++) fails += !r[k].pass;
  if (json) {
    cJSON* arr = cJSON_CreateArray();
    for (int k = 0; arr && k < n; k++) {
      cJSON* o = cJSON_CreateObject();
      cJSON_AddStringToObject(o, "name", r[k].name);
      cJSON_AddStringToObject(o, "form", r[k].form);
      cJSON_AddStringToObject(o, "quantity", r[k].quantity);
      cJSON_AddNumberToObject(o, "measured", r[k].measured);
      cJSON_AddNumberToObject(o, "reference", r[k].reference);
      cJSON_AddNumberToObject(o, "error", r[k].error);
      cJSON_AddNumberToObject(o, "tolerance", r[k].tolerance);
      cJSON_AddBoolToObject(o, "pass", r[k].pass);
      cJSON_AddStringToObject(o, "note", r[k].note);
      cJSON_AddItemToArray(arr, o);
    }
    char* text = arr ? cJSON_Print(arr) : NULL;
    cJSON_Delete(arr);
    if (text) {
      fputs(text, stdout);
      fputc('\n', stdout);
      cJSON_free(text);
    }
  } else {
    printf("%-4s  %-30s %-9s %-40s %13s %13s %10s %10s\n", "", "case", "form", "quantity", "measured", "reference",
           "error", "tolerance");
    for (int k = 0; k < n; k++)
      printf("%-4s  %-30s %-9s %-40s %13.6g %13.6g %10.3g %10.3g\n", r[k].pass ? "ok" : "FAIL", r[k].name, r[k].form,
             r[k].quantity, r[k].measured, r[k].reference, r[k].error, r[k].tolerance);
    printf("%d checks, %d passed, %d failed (%.1f s)\n", n, n - fails, fails, cli_now() - t0);
  }
  vd_free(r, (size_t)n * sizeof *r);
  return fails ? EXIT_FAIL : EXIT_OK;
}
