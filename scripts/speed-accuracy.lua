-- The data behind scripts/chart-speed-accuracy: what each timestep costs
-- and what it gets wrong, against closed forms. Run by the seixo
-- executable: seixo scripts/speed-accuracy.lua OUTDIR
-- Writes OUTDIR/*.dat (gnuplot tables, '#' headers). Costs are the core's
-- wall-clock time inside its cycles (m:profile), not the Lua around them.
local out = assert(arg[1], "usage: seixo scripts/speed-accuracy.lua OUTDIR")
local FRACTIONS = {0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0}
local R, RHO = 0.01, 2500.0
local MASS = 4 / 3 * math.pi * R ^ 3 * RHO

local function open(name, header)
  local f = assert(io.open(out .. "/" .. name, "w"))
  f:write(header, "\n")
  return f
end

local function core_seconds(m) return m:profile{print = false}.cycle_seconds end

local function energy(m)
  local e = m:energy()
  return e.kinetic + e.strain
end

-- Two equal spheres approaching head-on at v each; returns the contact
-- time (the gap's zero crossings, interpolated between whole steps), the
-- restitution and the core's time, at dt = f x the critical step.
local function impact(mat, f, v)
  local m = seixo.model{dim = 3}
  m:material("s", mat)
  local a = m:ball{pos = {-R - 1e-4, 0, 0}, vel = {v, 0, 0}, radius = R}
  local b = m:ball{pos = {R + 1e-4, 0, 0}, vel = {-v, 0, 0}, radius = R}
  local crit = m:critical_timestep()
  m:set_timestep(f * crit)
  local dt = m:timestep()
  local function gap() return b.pos[1] - a.pos[1] - 2 * R end
  local g0, t0, t1 = gap(), nil, nil
  while not t1 do
    m:cycle(1)
    local g = gap()
    if not t0 and g < 0 then t0 = m:time() - dt * g / (g - g0) end
    if t0 and g >= 0 and g0 < 0 then t1 = m:time() - dt * g / (g - g0) end
    g0 = g
    if m:step() > 1e7 then error("no separation") end
  end
  m:cycle(2) -- the contact's last force is in the velocities of the next half step
  local after = b.vel[1] - a.vel[1]
  local t = core_seconds(m)
  m:close()
  return t1 - t0, after / (2 * v), t, crit
end

-- 1. impacts: linear spring-dashpot and elastic Hertz
do
  local v, beta, kn = 0.5, 0.2, 1e6
  local mstar, k = MASS / 2, kn / 2 -- springs in series (4-22)
  local w0 = math.sqrt(k / mstar)
  local tc_lin = math.pi / (w0 * math.sqrt(1 - beta ^ 2))
  local e_lin = math.exp(-beta * math.pi / math.sqrt(1 - beta ^ 2))
  -- Hertz (4-25): Fn = K Un^1.5, K = 2 G sqrt(2 Rbar) / (3 (1 - nu)), Rbar = R for equal spheres
  local G, nu = 1e8, 0.25
  local K = 2 * G * math.sqrt(2 * R) / (3 * (1 - nu))
  local umax = (5 * mstar * (2 * v) ^ 2 / (4 * K)) ^ 0.4
  local tc_hz = 2.9432 * umax / (2 * v)
  local f = open("impact.dat", "# model fraction dt_over_crit core_seconds contact_time_rel_error restitution_abs_error")
  for _, case in ipairs({
    {"linear", {model = "linear", density = RHO, kn = kn, ks = kn, friction = 0, viscous_normal = beta}, tc_lin, e_lin},
    {"hertz", {model = "hertz", density = RHO, shear_modulus = G, poisson = nu, friction = 0}, tc_hz, 1.0},
  }) do
    for _, frac in ipairs(FRACTIONS) do
      local tc, e, t = impact(case[2], frac, v)
      f:write(string.format("%s %.3f %.3f %.6e %.6e %.6e\n", case[1], frac, frac, t,
                            math.abs(tc / case[3] - 1), math.abs(e - case[4])))
    end
    f:write("\n\n")
  end
  f:close()
end

-- 2. energy drift of an elastic, frictionless system: a cubic lattice of
-- spheres in a frictionless box, random velocities, no damping.
local function elastic_box(mat, frac, T)
  local m = seixo.model{dim = 3}
  m:material("s", mat)
  local n, s = 6, 2.05 * R
  m:wall{kind = "box", min = {0, 0, 0}, max = {n * s, n * s, n * s}, kn = 2e6, ks = 2e6, friction = 0}
  local seed = 12345
  local function rnd() -- a small LCG: the same velocities for every run
    seed = (seed * 1103515245 + 12345) % 2147483648
    return seed / 2147483648 - 0.5
  end
  for i = 0, n - 1 do
    for j = 0, n - 1 do
      for k = 0, n - 1 do
        m:ball{pos = {(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s}, radius = R, vel = {rnd(), rnd(), rnd()}}
      end
    end
  end
  local crit = m:critical_timestep()
  m:set_timestep(frac * crit)
  local e0, worst = energy(m), 0
  local steps = math.ceil(T / m:timestep())
  local chunk = math.max(1, steps // 200)
  local done = 0
  while done < steps do
    local k = math.min(chunk, steps - done)
    m:cycle(k)
    done = done + k
    worst = math.max(worst, math.abs(energy(m) / e0 - 1))
  end
  local t = core_seconds(m)
  m:close()
  return worst, t
end

do
  local f = open("drift.dat", "# model fraction core_seconds max_relative_energy_drift (0.05 s of model time)")
  for _, case in ipairs({
    {"linear", {model = "linear", density = RHO, kn = 2e6, ks = 2e6, friction = 0}},
    {"hertz", {model = "hertz", density = RHO, shear_modulus = 1e8, poisson = 0.25, friction = 0}},
  }) do
    for _, frac in ipairs(FRACTIONS) do
      local drift, t = elastic_box(case[2], frac, 0.05)
      f:write(string.format("%s %.3f %.6e %.6e\n", case[1], frac, t, drift))
    end
    f:write("\n\n")
  end
  f:close()
end

-- 3. stability: a sphere squeezed between two parallel planes (linear, no
-- damping, no gravity), a bound oscillator; energy growth over 2000 steps
-- past the central-difference limit dt = 2/omega, and where seixo's guard
-- stops the run.
do
  local kn = 1e6
  local k = 2 * (kn * kn / (kn + kn)) -- two contacts, each ball and wall in series (4-22)
  local limit = 2 / math.sqrt(k / MASS)
  local f = open("stability.dat", "# fraction_of_crit energy_growth guard(1 = the run was stopped as unstable)")
  local crit_ref, trip
  for i = 0, 35 do
    local frac = 0.5 + i * 0.1
    local m = seixo.model{dim = 3}
    m:material("s", {model = "linear", density = RHO, kn = kn, ks = kn, friction = 0})
    m:wall{kind = "plane", point = {-R + 5e-5, 0, 0}, normal = {1, 0, 0}, kn = kn, ks = kn, friction = 0}
    m:wall{kind = "plane", point = {R - 4e-5, 0, 0}, normal = {-1, 0, 0}, kn = kn, ks = kn, friction = 0}
    m:ball{pos = {0, 0, 0}, radius = R}
    local crit = m:critical_timestep()
    crit_ref = crit
    m:set_timestep(frac * crit)
    local e0, worst = energy(m), 1
    local ok = true
    for _ = 1, 40 do
      ok = pcall(m.cycle, m, 50)
      if not ok then break end
      worst = math.max(worst, energy(m) / e0)
    end
    if not ok and not trip then trip = frac end
    f:write(string.format("%.3f %.6e %d\n", frac, worst, ok and 0 or 1))
    m:close()
  end
  f:close()
  local g = open("stability-marks.dat", "# theoretical_limit_fraction guard_trip_fraction")
  g:write(string.format("%.6f %.6f\n", limit / crit_ref, trip or -1))
  g:close()
end

-- 4. quasi-static: settling a bed under gravity to an unbalanced-force
-- ratio of 1e-3, against local damping and density scaling (density x s
-- and gravity / s, so the weights and the static answer stay the same
-- while the automatic timestep grows by sqrt(s)).
do
  local f = open("quasistatic.dat", "# damping scaling steps core_seconds settled(1/0) mean_overlap_um coordination")
  for _, alpha in ipairs({0.1, 0.3, 0.5, 0.7}) do
    for _, sc in ipairs({1, 10, 100}) do
      local m = seixo.model{dim = 3, gravity = {0, 0, -9.81 / sc}}
      m:material("s", {model = "linear", density = RHO * sc, kn = 1e6, ks = 1e6, friction = 0.5, damping = alpha})
      m:wall{kind = "box", min = {0, 0, 0}, max = {0.12, 0.12, 0.3}, kn = 1e6, ks = 1e6}
      m:generate{count = 250, radius = {0.008, 0.01}, region = {box = {{0, 0, 0}, {0.12, 0.12, 0.3}}}, seed = 4}
      local why, _, steps = m:solve{ratio = 1e-3, steps = 100000, every = 50}
      local sum, nc = 0, 0
      for c in m:contacts() do
        if c.kind ~= "wall" then sum, nc = sum + c.overlap, nc + 1 end
      end
      f:write(string.format("%.2f %d %d %.6e %d %.6e %.6f\n", alpha, sc, steps, core_seconds(m),
                            why == "ratio" and 1 or 0, nc > 0 and sum / nc * 1e6 or 0, 2 * nc / m:ball_count()))
      m:close()
    end
    f:write("\n\n")
  end
  f:close()
end

-- 5. quasi-static loading: the peak strength of one bonded specimen in
-- unconfined compression (seixo.lab, 2D) against the axial strain rate, in
-- multiples of the library's default (7e-8 per step), with the cost: a
-- rate is quasi-static where halving it no longer moves the peak.
do
  local lab = require "seixo.lab"
  local spec = lab.specimen{dim = 2, shape = "rect", width = 0.02, height = 0.04, radius = {0.4e-3, 0.66e-3},
                            seed = 1, path = out .. "/loading-rate-specimen.h5", log = false}
  local f = open("loading-rate.dat", "# rate_factor strain_rate_per_s peak_MPa steps wall_seconds mean_ratio")
  for _, k in ipairs({0.25, 0.5, 1, 2, 4, 8, 16}) do
    local m = seixo.load(spec.path)
    local rate = k * 7e-8 / m:timestep()
    m:close()
    local r = lab.ucs(spec, {strain_rate = rate, log = false})
    f:write(string.format("%g %.6e %.6f %d %.6e %.6e\n", k, rate, r.peak / 1e6, r.steps, r.wall_time, r.mean_ratio))
  end
  f:close()
  os.remove(spec.path)
end
