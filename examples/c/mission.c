/*
 * aloft from C: load the built-in DJI M100, plan the built-in demonstration mission and print the
 * energy it costs, then the summary JSON (the same text as `aloft mission --format json`).
 *
 * Build (from the repository root, after `cargo build -p aloft-ffi --release`):
 *   cc -std=c99 -Wall -Wextra -I crates/ffi/include examples/c/mission.c \
 *      target/release/libaloft_ffi.a -lpthread -ldl -lm -o aloft-mission
 * or against the shared library:
 *   cc -std=c99 -I crates/ffi/include examples/c/mission.c -L target/release -laloft_ffi \
 *      -Wl,-rpath,target/release -o aloft-mission
 *
 * Exit status: 0 when the mission is feasible, 1 when not, 2 on an error.
 */
#include <stdio.h>

#include "aloft.h"

/* Print the error of a failed call and leave with status 2. */
static int fail(const char *what, AloftStatus status) {
    fprintf(stderr, "aloft-mission: %s failed (status %d): %s\n", what, (int)status,
            aloft_last_error_message());
    return 2;
}

int main(void) {
    AloftVehicle *m100 = NULL;
    AloftPlan *plan = NULL;
    char *json = NULL;
    double energy_wh = 0.0;
    int feasible = 0;
    int code = 2;
    AloftStatus s;

    s = aloft_vehicle_builtin("dji-m100", &m100);
    if (s != ALOFT_STATUS_OK) return fail("aloft_vehicle_builtin", s);

    /* NULL mission: the built-in demonstration; NULL options: the CLI's defaults. */
    s = aloft_mission_plan(m100, NULL, NULL, &plan);
    if (s != ALOFT_STATUS_OK) { code = fail("aloft_mission_plan", s); goto out; }

    s = aloft_plan_energy_wh(plan, &energy_wh);
    if (s != ALOFT_STATUS_OK) { code = fail("aloft_plan_energy_wh", s); goto out; }
    s = aloft_plan_feasible(plan, &feasible);
    if (s != ALOFT_STATUS_OK) { code = fail("aloft_plan_feasible", s); goto out; }
    s = aloft_plan_json(plan, &json);
    if (s != ALOFT_STATUS_OK) { code = fail("aloft_plan_json", s); goto out; }

    /* %.1f as the CLI's table prints it; %.17g round-trips the double exactly. */
    printf("energy used: %.1f Wh\n", energy_wh);
    printf("energy_wh: %.17g\n", energy_wh);
    printf("feasible: %s\n", feasible ? "yes" : "no");
    printf("%s\n", json);
    code = feasible ? 0 : 1;

out:
    aloft_string_free(json);
    aloft_plan_free(plan);
    aloft_vehicle_free(m100);
    return code;
}
