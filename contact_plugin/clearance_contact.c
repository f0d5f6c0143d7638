// The library of MuJoCo engine plugins that `import mujoco` loads for clearance (through the
// mujoco.plugins entry point): clearance.journal_bearing (journal_bearing.c, the exact contact of
// a revolute clearance joint), clearance.work (work_meter.c, the energy meter's work sensor),
// clearance.backlash_stop (backlash_stop.c, the gear mesh's law at the ends of a backlash band) and
// clearance.slider_guide (slider_guide.c, a slider with play in its guide).
// Each file's header comment is its plugin's full specification; plugin_util.c holds what they
// share and contact_laws.c the normal laws (the operations of contact_calibration/laws.py).

#include <mujoco/mjplugin.h>

#include "plugin_util.h"

mjPLUGIN_LIB_INIT(clearance_journal_bearing) {
  cl_register_journal_bearing();
  cl_register_work_meter();
  cl_register_backlash_stop();
  cl_register_slider_guide();
}
