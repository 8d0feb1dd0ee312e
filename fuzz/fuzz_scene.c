// SPDX-License-Identifier: MIT
// libFuzzer target: harvest scene JSON (docs/formats.md "Harvest scenes") through the parser and
// the per-episode scenes of a batch. Every path of the parser must end in VD_OK or a
// VD_ERR_FORMAT that names the field, without leaking what it allocated.
#include "fuzz_common.h"
#include "verdant/robot.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_scene s;
  vd_status st = vd_scene_parse((const char*)data, size, "/scenes/fuzz.json", &s, &err);
  if (st == VD_OK) {
    // what the parser accepted is in range, and an episode scene of it too
    if (!(s.duration > 0 && s.control_dt > 0 && s.sim_opt.dt > 0 && s.fps > 0)) __builtin_trap();
    if (s.nplant_set < 0 || s.nplant_set > VD_SCENE_MAX_SET) __builtin_trap();
    vd_scene e;
    uint64_t ts;
    if (vd_scene_episode(&s, 7, 3, &e, &ts, &err) == VD_OK) {
      if (s.episodes.speed[1] > s.episodes.speed[0] &&
          !(e.method.speed >= s.episodes.speed[0] && e.method.speed <= s.episodes.speed[1]))
        __builtin_trap();
      vd_scene_free(&e);
    }
    vd_scene_free(&s);
  } else if (st != VD_ERR_FORMAT && st != VD_ERR_NOMEM && st != VD_ERR_LIMIT) {
    __builtin_trap();
  } else if (!err.msg[0]) {
    __builtin_trap();  // an error says what is wrong
  }
  if (vd_alloc_bytes() != before) __builtin_trap();  // nothing leaked
  return 0;
}
