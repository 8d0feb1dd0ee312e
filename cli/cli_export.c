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
    "Write a plant (an .lpy file, derived on the fly, or a plant .json) for a robot simulator,\n"
    "flexible by default: the plant's rods (the same model `verdant sim` steps) as a tree of\n"
    "links named <label>_<instance>_<k>, joined by three spring joints each (bending about the\n"
    "rod's d1 and d2, twist about d3) whose stiffness is the rods' EI/l and GJ/l, with the rods'\n"
    "masses and inertias on every link; a capsule (MJCF) or cylinder (URDF, SDF) per rod segment,\n"
    "a sphere per fruit, a mesh per leaf (given a thickness, closed), on the link it rides on.\n"
    "URDF and SDF write the meshes as OBJ files into OUT_meshes/ and hold the base in the world\n"
    "by a fixed joint; URDF puts its springs in <gazebo> blocks. MJCF holds the meshes inline and\n"
    "can be included beside a robot (plant geoms: contype 2, conaffinity 1):\n"
    "  <mujoco><include file=\"arm.xml\"/><include file=\"plant.xml\"/></mujoco>\n"
    "--static writes the plant as it was drawn instead: one rigid link per organ instance\n"
    "(<label>_<instance>), no masses, fixed joints, a static SDF model, MJCF bodies without joints.\n"
    "docs/formats.md, \"Robot simulators\".\n"
    "\n"
    "options:\n"
    "  -o, --output OUT      .urdf, .sdf or .xml (MJCF)\n"
    "      --name NAME       model name, and the prefix NAME/ of the MJCF names (default plant)\n"
    "      --pos X,Y,Z       where the plant stands (m): the MJCF root body's and the SDF model's\n"
    "                        pose (default 0,0,0)\n"
    "      --leaf-thickness M  thickness of leaves and other open meshes (m, default 0.0002)\n"
    "      --links-per-organ N|auto|rigid\n"
    "                        links of each organ: auto one per rod segment (default), N the\n"
    "                        organ's rods in N links (stiffness of the rods in series), rigid one\n"
    "                        link per organ on fixed joints (masses and inertias still given)\n"
    "      --damping-ratio Z joint damping as a fraction of critical (default 0.1)\n"
    "      --static          the drawn plant: rigid organs, no masses (the export before 0.9)\n"
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
  int check = 0, is_static = 0;
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
                !strcmp(a, "--pos") || !strcmp(a, "--leaf-thickness") || !strcmp(a, "--check-with") ||
                !strcmp(a, "--links-per-organ") || !strcmp(a, "--damping-ratio");
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
    } else if (!strcmp(a, "--links-per-organ")) {
      double n = 0;
      if (val && !strcmp(val, "auto"))
        def.links_per_organ = 0;
      else if (val && !strcmp(val, "rigid"))
        def.links_per_organ = -1;
      else if (cli_parse_num(val, &n) && n >= 1 && n <= 1e6 && n == floor(n))
        def.links_per_organ = (int)n;
      else
        return cli_usage_error("export", "--links-per-organ expects auto, rigid or a whole number "
                                         ">= 1, got '%s'", val);
    } else if (!strcmp(a, "--damping-ratio")) {
      if (!cli_parse_num(val, &def.damping_ratio) || def.damping_ratio < 0)
        return cli_usage_error("export", "--damping-ratio expects a number >= 0, got '%s'", val);
    } else if (!strcmp(a, "--static")) {
      is_static = 1;
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
  vd_sim_model* sm = NULL;
  vd_export_rods rods;
  memset(&rods, 0, sizeof rods);
  vd_status st = cli_load_plant(&po, &spec, &info, &err);
  if (!st) st = vd_plant_compile(spec, &m, &err);
  cli_blame_input(&err, po.path);
  int code = EXIT_OK;
  if (st) {
    code = cli_report("export", &err, st);
    goto done;
  }
  // the rods (default settings, as `verdant sim` builds them) for a flexible plant
  if (!is_static) {
    vd_sim_def sdef = vd_sim_def_default();
    st = vd_sim_build(m, &sdef, &sm, &err);
    if (!st) st = vd_sim_export_rods(sm, m, &rods, &err);
    if (st) {
      cli_blame_input(&err, po.path);
      code = cli_report("export", &err, st);
      goto done;
    }
    def.rods = &rods;
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
  vd_sim_export_rods_free(&rods);
  vd_sim_model_destroy(sm);
  vd_model_destroy(m);
  vd_plant_spec_destroy(spec);
  cli_grow_info_free(&info);
  return code;
}
