/* A C peer for robowire's spline shared memory, written from the layout of spec spline-shm.md
 * (packed structs, like the vendor header). Modes:
 *   layout                 print "name offset size" for every field and struct
 *   client NAME            act as the motion controller against a running daemon
 *   daemon NAME CYCLES     create NAME and act as the daemon for CYCLES 1 ms cycles
 * Flags are accessed with C11-style atomics (release on set, acquire on test). */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

typedef struct __attribute__((packed)) { float p_des, v_des, kp, kd, t_ff; } joint_control;
typedef struct __attribute__((packed)) { joint_control abad, hip, knee, foot; int32_t flags; } leg_control;
typedef struct __attribute__((packed)) { leg_control legs[4]; uint32_t consumer_flags[2]; } spline_cmd_data;
typedef struct __attribute__((packed)) { int32_t flags; float p, v, t; } joint_state;
typedef struct __attribute__((packed)) { joint_state abad, hip, knee, foot; } leg_state;
typedef struct __attribute__((packed)) { leg_state legs[4]; uint32_t consumer_flags[2]; } spline_state_data;
typedef struct __attribute__((packed)) { spline_cmd_data cmd; spline_state_data state; } spline_data;
typedef struct __attribute__((packed)) { uint64_t timestamp; float acc[3], gyro[3], q[4]; } nav_imu;

#define P(type, field) printf("%s.%s %zu %zu\n", #type, #field, offsetof(type, field), sizeof(((type *)0)->field))
#define S(type) printf("%s %d %zu\n", #type, -1, sizeof(type))

static void layout(void) {
    S(joint_control); P(joint_control, p_des); P(joint_control, v_des); P(joint_control, kp); P(joint_control, kd); P(joint_control, t_ff);
    S(leg_control); P(leg_control, abad); P(leg_control, hip); P(leg_control, knee); P(leg_control, foot); P(leg_control, flags);
    S(spline_cmd_data); P(spline_cmd_data, legs); P(spline_cmd_data, consumer_flags);
    S(joint_state); P(joint_state, flags); P(joint_state, p); P(joint_state, v); P(joint_state, t);
    S(leg_state); P(leg_state, abad); P(leg_state, hip); P(leg_state, knee); P(leg_state, foot);
    S(spline_state_data); P(spline_state_data, legs); P(spline_state_data, consumer_flags);
    S(spline_data); P(spline_data, cmd); P(spline_data, state);
    S(nav_imu); P(nav_imu, timestamp); P(nav_imu, acc); P(nav_imu, gyro); P(nav_imu, q);
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static spline_data *map(const char *name, int create) {
    int fd = shm_open(name, create ? (O_CREAT | O_RDWR) : O_RDWR, 0660);
    if (fd < 0) { perror("shm_open"); exit(2); }
    if (create && ftruncate(fd, 10240) != 0) { perror("ftruncate"); exit(2); }
    void *p = mmap(NULL, 10240, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    if (p == MAP_FAILED) { perror("mmap"); exit(2); }
    return (spline_data *)p;
}

static joint_control *joint(leg_control *leg, int j) { return &leg->abad + j; }
static joint_state *joint_s(leg_state *leg, int j) { return &leg->abad + j; }

/* The controller: command p_des = 0.1 * (4 * leg + joint), kp = 7, then wait for fresh state. */
static int client(const char *name) {
    spline_data *d = map(name, 0);
    for (int l = 0; l < 4; l++) {
        for (int j = 0; j < 4; j++) {
            joint_control *c = joint(&d->cmd.legs[l], j);
            c->p_des = 0.1f * (float)(4 * l + j); c->v_des = 0; c->kp = 7; c->kd = 0.5f; c->t_ff = 0;
        }
        d->cmd.legs[l].flags = 1;
    }
    __atomic_store_n(&d->cmd.consumer_flags[0], 1, __ATOMIC_RELEASE);
    double deadline = now_s() + 5.0;
    /* Drop any state published before our command, then wait for one after it. */
    __atomic_store_n(&d->state.consumer_flags[0], 0, __ATOMIC_RELEASE);
    while (__atomic_load_n(&d->cmd.consumer_flags[0], __ATOMIC_ACQUIRE) != 0) {
        if (now_s() > deadline) { fprintf(stderr, "daemon never consumed the command\n"); return 3; }
    }
    while (__atomic_load_n(&d->state.consumer_flags[0], __ATOMIC_ACQUIRE) == 0) {
        if (now_s() > deadline) { fprintf(stderr, "no fresh state\n"); return 3; }
    }
    spline_state_data s;
    memcpy(&s, &d->state, sizeof s);
    __atomic_store_n(&d->state.consumer_flags[0], 0, __ATOMIC_RELEASE);
    for (int l = 0; l < 4; l++)
        for (int j = 0; j < 4; j++) {
            joint_state *js = joint_s(&s.legs[l], j);
            printf("state %d %d %08x %.6f\n", l, j, (unsigned)js->flags, js->p);
        }
    return 0;
}

/* The daemon: echo each fresh command's p_des as position, flags 0x00304101, for CYCLES ms. */
static int daemon_mode(const char *name, int cycles) {
    spline_data *d = map(name, 1);
    spline_cmd_data cmd;
    memset(&cmd, 0, sizeof cmd);
    int fresh = 0;
    for (int i = 0; i < cycles; i++) {
        if (__atomic_load_n(&d->cmd.consumer_flags[0], __ATOMIC_ACQUIRE) != 0) {
            memcpy(&cmd.legs, &d->cmd.legs, sizeof cmd.legs);
            __atomic_store_n(&d->cmd.consumer_flags[0], 0, __ATOMIC_RELEASE);
            fresh++;
        }
        for (int l = 0; l < 4; l++)
            for (int j = 0; j < 4; j++) {
                joint_state *js = joint_s(&d->state.legs[l], j);
                js->flags = 0x00304101; js->p = joint(&cmd.legs[l], j)->p_des; js->v = 0; js->t = joint(&cmd.legs[l], j)->kp;
            }
        __atomic_store_n(&d->state.consumer_flags[0], 1, __ATOMIC_RELEASE);
        __atomic_store_n(&d->state.consumer_flags[1], 1, __ATOMIC_RELEASE);
        struct timespec ms = {0, 1000000};
        nanosleep(&ms, NULL);
    }
    printf("fresh %d\n", fresh);
    shm_unlink(name);
    return 0;
}

int main(int argc, char **argv) {
    if (argc >= 2 && strcmp(argv[1], "layout") == 0) { layout(); return 0; }
    if (argc >= 3 && strcmp(argv[1], "client") == 0) return client(argv[2]);
    if (argc >= 4 && strcmp(argv[1], "daemon") == 0) return daemon_mode(argv[2], atoi(argv[3]));
    fprintf(stderr, "usage: spline_peer layout | client NAME | daemon NAME CYCLES\n");
    return 1;
}
