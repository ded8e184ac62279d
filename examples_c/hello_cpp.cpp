/*
 * hello_cpp.cpp -- tissuesim from C++17: a small RAII wrapper around ts_world (in this file, not
 * in the header, which stays plain C), used to press a probe into the default organ and print
 * the contact force.
 *
 *   hello_cpp
 *
 * The scene: the embedded default organ (E 5 kPa, nu 0.45, 1060 kg/m^3) resting on its bottom
 * 10 %, gravity, dt 1 ms; a 1 cm probe sphere starting on its top is lowered by 15 mm over the
 * first 60 % of the steps, then held still.
 * TS_STEPS=N sets the number of steps (default 500). Exits with 1 on any failure status, or if
 * the tissue does not push the probe back up.
 *
 * Build: c++ -std=c++17 -Iinclude examples_c/hello_cpp.cpp -Ltarget/release -ltissuesim -o hello_cpp
 * Run:   LD_LIBRARY_PATH=target/release ./hello_cpp
 */
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tissuesim.h"

namespace tissuesim {

/* A failure status of the C API, with the call that failed and the thread's last error message. */
class Error : public std::runtime_error {
  public:
    Error(const char *call, ts_status status)
        : std::runtime_error(describe(call, status)), status_(status) {}
    ts_status status() const noexcept { return status_; }

  private:
    static std::string describe(const char *call, ts_status status) {
        std::string message(ts_last_error_message(nullptr, 0), '\0');
        ts_last_error_message(message.data(), message.size() + 1);
        return std::string(call) + ": " + ts_status_string(static_cast<int>(status)) + ": " +
               message;
    }
    ts_status status_;
};

inline void check(ts_status status, const char *call) {
    if (status != TS_STATUS_OK) throw Error(call, status);
}

/* Owns one ts_world: created in the constructor (throws on failure), freed in the destructor.
 * Movable, not copyable. Only the calls this example needs are wrapped. */
class World {
  public:
    explicit World(const ts_settings &settings) {
        check(ts_world_new(&settings, &world_), "ts_world_new");
    }
    World() : World(default_settings()) {}
    ~World() { ts_world_free(world_); }

    World(const World &) = delete;
    World &operator=(const World &) = delete;
    World(World &&other) noexcept : world_(std::exchange(other.world_, nullptr)) {}
    World &operator=(World &&other) noexcept {
        if (this != &other) {
            ts_world_free(world_);
            world_ = std::exchange(other.world_, nullptr);
        }
        return *this;
    }

    static ts_settings default_settings() {
        ts_settings settings;
        check(ts_settings_default(&settings), "ts_settings_default");
        return settings;
    }

    ts_world *get() const noexcept { return world_; }

    uint32_t add_default_organ(const ts_material &material) {
        uint32_t body = 0;
        check(ts_world_add_default_organ(world_, &material, nullptr, &body),
              "ts_world_add_default_organ");
        return body;
    }
    std::vector<double> positions(uint32_t body) const {
        size_t n = 0;
        check(ts_body_particle_count(world_, body, &n), "ts_body_particle_count");
        std::vector<double> x(3 * n);
        check(ts_body_positions(world_, body, x.data(), x.size()), "ts_body_positions");
        return x;
    }
    size_t fix_box(uint32_t body, const double (&lo)[3], const double (&hi)[3]) {
        size_t fixed = 0;
        check(ts_body_fix_box(world_, body, lo, hi, &fixed), "ts_body_fix_box");
        return fixed;
    }
    uint32_t add_sphere(double radius, const ts_pose &pose) {
        uint32_t tool = 0;
        check(ts_world_add_tool_sphere(world_, radius, &pose, nullptr, &tool),
              "ts_world_add_tool_sphere");
        return tool;
    }
    void set_pose(uint32_t tool, const ts_pose &pose) {
        check(ts_tool_set_pose(world_, tool, &pose), "ts_tool_set_pose");
    }
    void step() { check(ts_world_step(world_, nullptr), "ts_world_step"); }
    ts_wrench wrench(uint32_t tool) const {
        ts_wrench w;
        check(ts_tool_wrench(world_, tool, &w), "ts_tool_wrench");
        return w;
    }
    double time() const {
        double t = 0;
        check(ts_world_time(world_, &t), "ts_world_time");
        return t;
    }

  private:
    ts_world *world_ = nullptr;
};

}  // namespace tissuesim

static int run() {
    if (ts_version() != TISSUESIM_VERSION) {
        std::fprintf(stderr, "hello_cpp: header %s but library %s\n", TISSUESIM_VERSION_STRING,
                     ts_version_string());
        return 1;
    }
    const char *env = std::getenv("TS_STEPS");
    const long steps = std::max(1L, env ? std::atol(env) : 500L);

    tissuesim::World world;
    ts_material material;
    tissuesim::check(ts_material_default(&material), "ts_material_default");
    const uint32_t organ = world.add_default_organ(material);

    /* Bounding box; fix the bottom 10 % (the organ rests on it). */
    const std::vector<double> x = world.positions(organ);
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    for (size_t i = 0; i < x.size(); i += 3)
        for (int k = 0; k < 3; k++) {
            lo[k] = std::min(lo[k], x[i + k]);
            hi[k] = std::max(hi[k], x[i + k]);
        }
    const double fix_lo[3] = {lo[0] - 1, lo[1] - 1, lo[2] - 1};
    const double fix_hi[3] = {hi[0] + 1, lo[1] + 0.1 * (hi[1] - lo[1]), hi[2] + 1};
    const size_t fixed = world.fix_box(organ, fix_lo, fix_hi);

    /* The probe starts just above the highest particle within 1.5 cm of the centre in x-z. */
    const double cx = 0.5 * (lo[0] + hi[0]), cz = 0.5 * (lo[2] + hi[2]);
    double top = lo[1];
    for (size_t i = 0; i < x.size(); i += 3) {
        const double dx = x[i] - cx, dz = x[i + 2] - cz;
        if (dx * dx + dz * dz < 0.015 * 0.015) top = std::max(top, x[i + 1]);
    }
    const double radius = 0.01, depth = 0.015;
    ts_pose pose = {{cx, top + radius, cz}, {1, 0, 0, 0}};
    const double start_y = pose.position[1];
    const uint32_t probe = world.add_sphere(radius, pose);
    std::printf("tissuesim %s from C++: %zu particles, %zu fixed, probe r = %.0f mm\n",
                ts_version_string(), x.size() / 3, fixed, 1e3 * radius);

    ts_wrench w{};
    for (long s = 1; s <= steps; s++) {
        const double ramp = std::min(1.0, static_cast<double>(s) / (0.6 * static_cast<double>(steps)));
        pose.position[1] = start_y - depth * ramp;
        world.set_pose(probe, pose);
        world.step();
        w = world.wrench(probe);
        if (s % std::max(1L, steps / 5) == 0 || s == steps)
            std::printf("t = %.3f s  press %4.1f mm  force (%+.4f, %+.4f, %+.4f) N  contacts %u\n",
                        world.time(), 1e3 * (start_y - pose.position[1]), w.force[0], w.force[1],
                        w.force[2], w.contact_count);
    }

    /* A failing call throws, and the world is still freed by its destructor. */
    try {
        world.fix_box(organ + 1, fix_lo, fix_hi);
        std::fprintf(stderr, "hello_cpp: fixing an unknown body did not fail\n");
        return 1;
    } catch (const tissuesim::Error &e) {
        if (e.status() != TS_STATUS_UNKNOWN_BODY) throw;
        std::printf("expected error: %s\n", e.what());
    }

    if (!(w.force[1] > 0) || w.contact_count == 0) {
        std::fprintf(stderr, "hello_cpp: the tissue does not push the probe up (fy = %g N)\n",
                     w.force[1]);
        return 1;
    }
    std::printf("contact force on the probe: %.4f N upwards\n", w.force[1]);
    return 0;
}

int main() {
    try {
        return run();
    } catch (const std::exception &e) {
        std::fprintf(stderr, "hello_cpp: %s\n", e.what());
        return 1;
    }
}
