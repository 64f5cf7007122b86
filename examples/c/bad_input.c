/*
 * Bad input through the C ABI: every call below must return the expected error code with a
 * message, and none may crash or touch freed memory (run it under valgrind or ASan too).
 * Prints one line per case; exit status 0 when every case returned what it should, else 1.
 */
#include <stdio.h>
#include <string.h>

#include "aloft.h"

static int failures = 0;

static void expect(const char *what, AloftStatus got, AloftStatus want) {
    const char *msg = aloft_last_error_message();
    int ok = got == want && (want == ALOFT_STATUS_OK || (msg != NULL && strlen(msg) > 0));
    printf("%s %-42s status %d (want %d): %s\n", ok ? "ok  " : "FAIL", what, (int)got, (int)want,
           msg ? msg : "(null message)");
    if (!ok) failures++;
}

int main(void) {
    AloftVehicle *v = NULL;
    AloftVehicle *other = NULL;
    AloftPlan *plan = NULL;
    char *json = NULL;
    double w = 0.0;
    int stack_int = 0;
    const char bad_utf8[] = {'d', 'j', 'i', (char)0xff, (char)0xfe, 0};

    expect("NULL vehicle name", aloft_vehicle_builtin(NULL, &v), ALOFT_STATUS_NULL_POINTER);
    expect("NULL out pointer", aloft_vehicle_builtin("dji-m100", NULL), ALOFT_STATUS_NULL_POINTER);
    expect("invalid UTF-8 name", aloft_vehicle_builtin(bad_utf8, &v), ALOFT_STATUS_INVALID_UTF8);
    expect("unknown vehicle", aloft_vehicle_builtin("no-such-drone", &v), ALOFT_STATUS_NOT_FOUND);
    expect("malformed vehicle TOML", aloft_vehicle_from_toml("name = [", &v), ALOFT_STATUS_PARSE);
    expect("vehicle TOML with unknown key", aloft_vehicle_from_toml("name = \"x\"\nwings = 2\n", &v),
           ALOFT_STATUS_PARSE);

    expect("load the M100", aloft_vehicle_builtin("dji-m100", &v), ALOFT_STATUS_OK);
    expect("NULL vehicle handle", aloft_mission_plan(NULL, NULL, NULL, &plan),
           ALOFT_STATUS_NULL_POINTER);
    expect("malformed mission TOML", aloft_mission_plan(v, "[[segment]]\nkind = ", NULL, &plan),
           ALOFT_STATUS_PARSE);
    expect("malformed mission JSON", aloft_mission_plan(v, "{\"segment\": [", NULL, &plan),
           ALOFT_STATUS_PARSE);
    expect("invalid UTF-8 mission", aloft_mission_plan(v, bad_utf8, NULL, &plan),
           ALOFT_STATUS_INVALID_UTF8);
    expect("empty mission", aloft_mission_plan(v, "name = \"empty\"\n", NULL, &plan),
           ALOFT_STATUS_MISSION);
    expect("malformed options JSON", aloft_mission_plan(v, NULL, "{\"payload_kg\": }", &plan),
           ALOFT_STATUS_PARSE);
    expect("unknown option key", aloft_mission_plan(v, NULL, "{\"payload\": 1}", &plan),
           ALOFT_STATUS_PARSE);
    expect("payload beyond the airframe", aloft_mission_plan(v, NULL, "{\"payload_kg\": 40}", &plan),
           ALOFT_STATUS_MISSION);
    expect("unknown battery", aloft_mission_plan(v, NULL, "{\"battery\": \"nope\"}", &plan),
           ALOFT_STATUS_NOT_FOUND);
    expect("NaN airspeed", aloft_vehicle_power_w(v, 0.0 / 0.0, 0, 0, 0, &w),
           ALOFT_STATUS_INVALID_INPUT);
    expect("NULL power out pointer", aloft_vehicle_power_w(v, 5, 0, 0, 0, NULL),
           ALOFT_STATUS_NULL_POINTER);
    expect("malformed flight state", aloft_vehicle_power_json(v, "{\"airspeed_mps\": 5,", &json), ALOFT_STATUS_PARSE);
    expect("endurance with gusts", aloft_endurance_json(v,
           "{\"wind\": {\"speed_mps\": 5, \"from_deg\": 0, \"gust_std_mps\": 1}}", &json),
           ALOFT_STATUS_INVALID_INPUT);

    expect("plan the demo", aloft_mission_plan(v, NULL, NULL, &plan), ALOFT_STATUS_OK);
    expect("summary JSON", aloft_plan_json(plan, &json), ALOFT_STATUS_OK);
    expect("plan passed as a vehicle", aloft_vehicle_free((AloftVehicle *)plan),
           ALOFT_STATUS_BAD_HANDLE);
    expect("string passed as a plan", aloft_plan_free((AloftPlan *)json), ALOFT_STATUS_BAD_HANDLE);
    expect("free a pointer aloft never returned", aloft_string_free((char *)&stack_int),
           ALOFT_STATUS_BAD_HANDLE);

    expect("free the string", aloft_string_free(json), ALOFT_STATUS_OK);
    expect("free the string again", aloft_string_free(json), ALOFT_STATUS_BAD_HANDLE);
    expect("free the plan", aloft_plan_free(plan), ALOFT_STATUS_OK);
    expect("use the freed plan", aloft_plan_energy_wh(plan, &w), ALOFT_STATUS_BAD_HANDLE);
    expect("free the plan again", aloft_plan_free(plan), ALOFT_STATUS_BAD_HANDLE);
    expect("load a second vehicle", aloft_vehicle_builtin("aec-quadrotor", &other), ALOFT_STATUS_OK);
    expect("free the vehicle", aloft_vehicle_free(v), ALOFT_STATUS_OK);
    expect("free the vehicle again", aloft_vehicle_free(v), ALOFT_STATUS_BAD_HANDLE);
    expect("free the second vehicle", aloft_vehicle_free(other), ALOFT_STATUS_OK);
    expect("free NULL", aloft_vehicle_free(NULL), ALOFT_STATUS_OK);

    printf("%d failure(s)\n", failures);
    return failures == 0 ? 0 : 1;
}
