/* The scene blob in flash: the .mls file named by FW_SCENE_FILE, 8-byte aligned (read_scene needs it),
   between the symbols fw_scene and fw_scene_end. */
  .section .scene, "a"
  .balign 8
  .global fw_scene
  .global fw_scene_end
fw_scene:
  .incbin FW_SCENE_FILE
fw_scene_end:
