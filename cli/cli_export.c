// SPDX-License-Identifier: MIT
// verdant export: a plant for robot simulators, as URDF, SDF or MuJoCo MJCF (by the output's
// extension), with --check loading an MJCF in MuJoCo (alone, or in a scene with a robot).
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* export_help =
    "usage: verdant export PLANT -o OUT.urdf|OUT.sdf|OUT.xml [options]\n"
    "\n"
    "Write a plant (an .lpy file, derived on the fly, or a plant .json) for a robot simulator:\n"
    "every organ instance is a link (URDF, SDF) or body (MuJoCo MJCF, .xml) named\n"
    "<label>_<instance> with a visual and a collision shape per primitive: a cylinder (URDF,\n"
    "SDF) or capsule (MJCF) of the segment's mean radius, a sphere per fruit, a mesh per leaf\n"
    "(given a thickness, closed). URDF and SDF write the meshes as OBJ files into\n"
    "OUT_meshes/; MJCF holds them inline and can be included beside a robot:\n"
    "  <mujoco><include file=\"arm.xml\"/><include file=\"plant.xml\"/></mujoco>\n"
    "The plant is static (fixed joints, a static SDF model, MJCF bodies without joints).\n"
    "\n"
    "options:\n"
    "  -o, --output OUT      .urdf, .sdf or .xml (MJCF)\n"
    "      --name NAME       model name, and the prefix NAME/ of the MJCF names (default plant)\n"
    "      --pos X,Y,Z       where the plant stands (m): the MJCF root body's and the SDF model's\n"
    "                        pose (default 0,0,0)\n"
    "      --leaf-thickness M  thickness of leaves and other open meshes (m, default 0.0002)\n"
    "      --check           load the MJCF in MuJoCo and print what it holds (JSON)\n"
    "      --check-with ROBOT.xml\n"
    "                        the same in a scene with a robot's MJCF: the JSON counts the\n"
    "                        contacts between the plant and the robot\n";

int cli_export(int argc, char** argv) {
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  vd_export_def def = vd_export_def_default();
  const char* out = NULL;
  const char* with = NULL;
  int check = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      fputs(export_help, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
    int r = cli_plant_opt(&po, "export", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    const char* val = i + 1 < argc ? argv[i + 1] : NULL;
    int takes = !strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--name") ||
                !strcmp(a, "--pos") || !strcmp(a, "--leaf-thickness") || !strcmp(a, "--check-with");
    if (takes && !val) return cli_usage_error("export", "%s needs a value", a);
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (out) return cli_usage_error("export", "-o given twice");
      out = val;
    } else if (!strcmp(a, "--name")) {
      def.name = val;
    } else if (!strcmp(a, "--pos")) {
      if (!cli_parse_vec3(val, &def.pos))
        return cli_usage_error("export", "--pos expects X,Y,Z in metres, got '%s'", val);
    } else if (!strcmp(a, "--leaf-thickness")) {
      if (!cli_parse_num(val, &def.leaf_thickness) || def.leaf_thickness <= 0 ||
          def.leaf_thickness >= 0.1)
        return cli_usage_error("export", "--leaf-thickness expects metres in (0, 0.1), got '%s'", val);
    } else if (!strcmp(a, "--check")) {
      check = 1;
    } else if (!strcmp(a, "--check-with")) {
      check = 1, with = val;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error("export", "unknown option '%s'", a);
    } else if (!po.path) {
      po.path = a;
      continue;
    } else {
      return cli_usage_error("export", "unexpected argument '%s'", a);
    }
    i += takes;
  }
  if (!po.path) return cli_usage_error("export", "missing PLANT (an .lpy or plant .json file)");
  if (!out) return cli_usage_error("export", "missing -o OUT.urdf, OUT.sdf or OUT.xml");
  if (cli_has_ext(out, ".urdf"))
    def.format = VD_EXPORT_URDF;
  else if (cli_has_ext(out, ".sdf"))
    def.format = VD_EXPORT_SDF;
  else if (cli_has_ext(out, ".xml"))
    def.format = VD_EXPORT_MJCF;
  else
    return cli_usage_error("export", "output '%s': use .urdf, .sdf or .xml (MuJoCo MJCF)", out);
  if (check && def.format != VD_EXPORT_MJCF)
    return cli_usage_error("export", "--check and --check-with load MJCF (.xml) in MuJoCo");
  // the files: the plant and the robot read, the file and its meshes written (the meshes of an
  // earlier export there that this one does not write go)
  cli_out_plant_opts(&po);
  cli_out_input("--check-with", with);
  cli_out_file("-o", out);
  if (def.format != VD_EXPORT_MJCF) {
    const char* slash = strrchr(out, '/');
    const char* dot = strrchr(out, '.');
    size_t n = dot && (!slash || dot > slash) ? (size_t)(dot - out) : strlen(out);
    char dir[4200];
    snprintf(dir, sizeof dir, "%.*s_meshes", (int)n, out);
    const char* members[1] = {"*.obj"};
    cli_out_folder("-o", dir, members, 1, 1);
  }
  if (cli_out_check("export")) return EXIT_USAGE;
  // the plant, its model, the files
  vd_error err = {0};
  vd_plant_spec* spec = NULL;
  vd_model* m = NULL;
  cli_grow_info info;
  memset(&info, 0, sizeof info);
  vd_status st = cli_load_plant(&po, &spec, &info, &err);
  if (!st) st = vd_plant_compile(spec, &m, &err);
  cli_blame_input(&err, po.path);
  int code = EXIT_OK;
  if (st) {
    code = cli_report("export", &err, st);
    goto done;
  }
  st = vd_geom_export(m, NULL, &def, out, &err);
  if (st) {
    code = cli_report("export", &err, st);
    if (st == VD_ERR_IO) code = EXIT_FAIL;
    goto done;
  }
  if (check) {
    // the plant alone, or in a scene with the robot (the file is under its temporary name until
    // the command ends)
    char now[4300];
    cli_out_current(out, now, sizeof now);
    const char* parts[2] = {with ? with : now, now};
    char prefix[64];
    snprintf(prefix, sizeof prefix, "%s/", def.name);
    vd_mjcf_info mi;
    st = vd_render_mjcf_info(with ? parts : parts + 1, with ? 2 : 1, prefix, &mi, &err);
    if (st) {
      code = cli_report("export", &err, st);
      goto done;
    }
    cJSON* j = cJSON_CreateObject();
    if (j) {
      cJSON_AddStringToObject(j, "file", out);
      if (with) cJSON_AddStringToObject(j, "robot", with);
      cJSON_AddNumberToObject(j, "bodies", mi.nbody);
      cJSON_AddNumberToObject(j, "geoms", mi.ngeom);
      cJSON_AddNumberToObject(j, "meshes", mi.nmesh);
      cJSON_AddNumberToObject(j, "joints", mi.njoint);
      cJSON_AddNumberToObject(j, "plant_bodies", mi.nbody_prefix);
      cJSON_AddNumberToObject(j, "plant_geoms", mi.ngeom_prefix);
      cJSON_AddNumberToObject(j, "contacts", mi.ncontact);
      cJSON_AddNumberToObject(j, "plant_robot_contacts", mi.ncontact_prefix);
      char* text = cJSON_Print(j);
      if (text) puts(text);
      cJSON_free(text);
      cJSON_Delete(j);
    }
  }
done:
  vd_model_destroy(m);
  vd_plant_spec_destroy(spec);
  cli_grow_info_free(&info);
  return code;
}
