# The CLI as a user runs it: a ten-minute VESC Tool log of an off-nominal machine holding every regime, its truth,
# an older header, midnight, and the usage, configuration and data errors.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# A file's lines as a CMake list, its semicolons (VESC Tool's separator, CMake's list separator) made commas.
function(read_lines path out)
  file(READ "${path}" content)
  string(REPLACE ";" "," content "${content}")
  string(REGEX REPLACE "\n$" "" content "${content}")
  string(REPLACE "\n" ";" content "${content}")
  set(${out} "${content}" PARENT_SCOPE)
endfunction()

function(run expected_code)
  execute_process(COMMAND "${EXE}" ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL expected_code)
    message(FATAL_ERROR "indep_vesc_log ${ARGN}: exit ${code}, expected ${expected_code}\n${out}${err}")
  endif()
  set(last_err "${err}" PARENT_SCOPE)
endfunction()

set(config "${SOURCE_DIR}/config/vesc-6374-outrunner.yaml")
run(0 --config "${config}" --seed 3 --duration-s 600 --psi-m-rel 0.2 --r-s-rel -0.25
    --out "${WORK_DIR}/log.csv" --truth "${WORK_DIR}/truth.json")
read_lines("${WORK_DIR}/log.csv" lines)
list(LENGTH lines n)
list(GET lines 0 header)
string(CONCAT expected_header
  "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
  "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
  "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;d_axis_voltage;q_axis_voltage;"
  "ms_today_setup;amp_hours_setup;amp_hours_charged_setup;watt_hours_setup;watt_hours_charged_setup;battery_level;"
  "battery_wh_tot;current_in_setup;current_motor_setup;speed_meters_per_sec;tacho_meters;tacho_abs_meters;num_vescs;"
  "ms_today_imu;roll;pitch;yaw;accX;accY;accZ;gyroX;gyroY;gyroZ;gnss_posTime;gnss_lat;gnss_lon;gnss_alt;gnss_gVel;"
  "gnss_vVel;gnss_hAcc;gnss_vAcc;")
string(REPLACE ";" "," expected_header "${expected_header}")
if(NOT header STREQUAL expected_header)
  message(FATAL_ERROR "log.csv: header '${header}'")
endif()
# 11 Hz on average for 600 s: 6600 rows, within the spread of the link.
if(n LESS 5800 OR n GREATER 7400)
  message(FATAL_ERROR "log.csv: ${n} lines")
endif()
list(GET lines 1000 row)
string(REGEX MATCHALL "," separators "${row}")
list(LENGTH separators cells)
if(NOT cells EQUAL 55)
  message(FATAL_ERROR "log.csv: a row with ${cells} values: ${row}")
endif()

file(READ "${WORK_DIR}/truth.json" truth)
string(JSON rows GET "${truth}" reads rows)
math(EXPR data_rows "${n} - 1")
string(JSON psi_ratio GET "${truth}" true_over_configured psi_m)
string(JSON rs_ratio GET "${truth}" true_over_configured r_s)
if(NOT rows EQUAL data_rows OR psi_ratio LESS 1.1999 OR psi_ratio GREATER 1.2001 OR rs_ratio LESS 0.7499
   OR rs_ratio GREATER 0.7501)
  message(FATAL_ERROR "truth.json: ${rows} rows for ${data_rows}, psi_m ratio ${psi_ratio}, r_s ratio ${rs_ratio}")
endif()
# Every regime the field shows, in numbers of rows.
foreach(regime bridge.modulating bridge.bridge_off angle.open_loop angle_locked segment.coast segment.flux_measurement
        transient excites_psi_m excites_r_s)
  string(JSON count ERROR_VARIABLE missing GET "${truth}" counts ${regime})
  if(missing OR count LESS 10)
    message(FATAL_ERROR "truth.json: ${count} rows of ${regime} ${missing}")
  endif()
endforeach()
string(JSON first_line GET "${truth}" rows 0 line)
string(JSON end_psi GET "${truth}" true_at_end psi_m_Wb)
if(NOT first_line EQUAL 2 OR end_psi LESS_EQUAL 0)
  message(FATAL_ERROR "truth.json: first row at line ${first_line}, psi_m at the end ${end_psi}")
endif()

# The oldest format: no header, 22 values, and a log across midnight.
run(0 --config "${config}" --seed 1 --duration-s 30 --header-version 0 --midnight --out "${WORK_DIR}/old.csv")
read_lines("${WORK_DIR}/old.csv" old)
list(GET old 0 first)
string(REGEX MATCHALL "," separators "${first}")
list(LENGTH separators cells)
if(NOT cells EQUAL 22 OR first MATCHES "ms_today")
  message(FATAL_ERROR "old.csv: first line '${first}'")
endif()
set(previous -1)
set(wrapped FALSE)
foreach(line IN LISTS old)
  string(REGEX MATCH "^[0-9]+" ms "${line}")
  if(ms LESS previous)
    set(wrapped TRUE)
  endif()
  set(previous ${ms})
endforeach()
if(NOT wrapped)
  message(FATAL_ERROR "old.csv: ms_today does not wrap at midnight")
endif()

run(64 --config "${config}" --set firmware.no_such_key=1 --out "${WORK_DIR}/x.csv")
if(NOT last_err MATCHES "unknown parameter 'firmware.no_such_key'")
  message(FATAL_ERROR "unknown parameter: ${last_err}")
endif()
run(64 --config "${config}" --rate-Hz 80 --out "${WORK_DIR}/x.csv")
run(78 --config "${WORK_DIR}/missing.yaml" --out "${WORK_DIR}/x.csv")
file(WRITE "${WORK_DIR}/bad.csv" "kind,duration_s,current_A\ncurrent,2,10\nsprint,1,5\n")
run(65 --config "${config}" --scenario "${WORK_DIR}/bad.csv" --out "${WORK_DIR}/x.csv")
if(NOT last_err MATCHES "bad.csv:3: kind 'sprint'")
  message(FATAL_ERROR "scenario error: ${last_err}")
endif()
run(0 --list-parameters)
