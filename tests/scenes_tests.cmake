# SPDX-License-Identifier: MIT
# Stability tests of the scene library: each is the runner on a named scene with its limits in
# --check (the runner exits 1 on a violation and prints the measured value). Short runs (--quick
# = fewer bodies, --steps) keep each under a few seconds; full runs are documented commands in
# samples/scenes/README.md. Only limits that hold today are registered; the Bullet re-creations'
# penetration and rest limits belong to the bridge-contacts issue and are added with its fixes.
if(SDFCCD_BUILD_BULLET_BRIDGE AND TARGET sdfccd_scenes)
  # sdfccd_add_scene_test(NAME SCENE ARGS...): ctest "scenes.NAME" runs sdfccd_scenes SCENE ARGS.
  function(sdfccd_add_scene_test name scene)
    add_test(NAME scenes.${name} COMMAND sdfccd_scenes ${scene} --quiet ${ARGN})
    set_tests_properties(scenes.${name} PROPERTIES LABELS "scenes;bullet")
  endfunction()

  # Bullet re-creations: no body tunnels through the SDFs (bridge, FWGSS + subdivision).
  sdfccd_add_scene_test(gimpact-demo.no_tunnel gimpact-demo --quick --steps 120 --check tunnelled=0,hit=1)
  sdfccd_add_scene_test(gimpact-shot-500.no_tunnel gimpact-shot-500 --quick --steps 90 --check tunnelled=0,hit=1)
  sdfccd_add_scene_test(sdf-box-btsdf.no_tunnel sdf-box-btsdf --quick --steps 200 --check tunnelled=0,hit=1)
  sdfccd_add_scene_test(landscape.no_tunnel landscape --quick --steps 120 --check tunnelled=0,hit=1)
  if(TARGET sdfccd_scenes_f64)
    add_test(NAME scenes.gimpact-shot-500.no_tunnel_f64
             COMMAND sdfccd_scenes gimpact-shot-500 --precision double --quiet --quick --steps 90 --check tunnelled=0,hit=1)
    set_tests_properties(scenes.gimpact-shot-500.no_tunnel_f64 PROPERTIES LABELS "scenes;bullet")
  endif()
endif()
