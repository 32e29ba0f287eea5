-- seixo.lab.frame: the loading frame the walled tests share (the
-- compression tests, the Brazilian test, a series): the specimen checked
-- and loaded from its file between two platens, the platens driven, the
-- loading rate's defaults, and a test's records and files at its end.
local check = require "seixo.check"
local tables = require "seixo.lab.tables"
local csv = require "seixo.lab.csv"
local polling = require "seixo.lab.polling"
local extents = require("seixo.lab.specimen").extents

local c = check.module("lab")
local fail, check_writable, number = c.fail, c.writable, c.number
local copy, merge = tables.copy, tables.merge

-- Fails unless spec is a specimen of lab.specimen or lab.open with the
-- fields the test fn reads (check.lua's names), up front.
local function check_spec(spec, fn, fields)
  if type(spec) == "table" and spec.periodic then
    fail("lab.%s: a periodic specimen is tested by lab.periodic's tests (no walls)", fn)
  end
  c.specimen(spec, fn, fields)
end

-- Loading direction: z in 3D, y in 2D.
local function axis_of(dim) return dim end

-- The default strain rate: an axial strain of 7e-8 per step. Quasi-static
-- loading needs many steps per wave transit of the specimen, and a wave
-- crosses a ball in a few steps whatever the stiffness; 7e-8 per step
-- brings a granite-like specimen to its peak in ~50,000 steps, where
-- halving the rate moves the peak by well under 1 % (examples/triaxial.lua).
local function default_rate(m) return 7e-8 / m:timestep() end

-- The inertial number I = strain rate x mean diameter x sqrt(density / p):
-- below about 1e-3 the loading is quasi-static (GDR MiDi 2004).
local function inertial_number(rate, spec, p, scale)
  if not (p > 0) then return math.huge end
  return rate * (spec.radius[1] + spec.radius[2]) * math.sqrt(scale * spec.material.density / p)
end

-- The options of open_test and finish, checked before a test (fn) starts:
-- out, a path prefix that can be written, and density_scale.
local function check_out_and_scale(opts, fn)
  if opts.out ~= nil then
    c.prefix(opts.out, fn)
    check_writable(opts.out .. ".csv", "out", fn)
  end
  number(opts.density_scale or 1, "density_scale", fn, "a factor in [1, 1e6]", function(v) return v >= 1 and v <= 1e6 end)
end

-- A test's start: the specimen loaded from its file, its extents and
-- centre, and the platens -- frictionless planes (lines) touching its ends
-- along the loading axis (its options checked: check_out_and_scale).
local function open_test(spec, opts, fn)
  local dim, ax = spec.dim, axis_of(spec.dim)
  local scale = opts.density_scale or 1
  local m = c.load(spec, fn)
  -- density scaling: the balls' density (so mass and inertia) times scale,
  -- the automatic timestep sqrt(m / k) times sqrt(scale); a quasi-static
  -- test's stresses do not depend on the mass, only its dynamics do
  if scale ~= 1 then m:material("rock", merge(spec.material, {density = scale * spec.material.density})) end
  local lo, hi = extents(m)
  local centre = {}
  for k = 1, dim do centre[k] = 0.5 * (lo[k] + hi[k]) end
  local down, up = {}, {}
  for k = 1, dim do down[k], up[k] = 0, 0 end
  up[ax], down[ax] = 1, -1
  local p_lo, p_hi = copy(centre), copy(centre)
  p_lo[ax], p_hi[ax] = lo[ax], hi[ax]
  local kind = dim == 3 and "plane" or "line"
  local bottom = m:wall{kind = kind, point = p_lo, normal = up, kn = spec.wall_kn, ks = 0, friction = 0}
  local top = m:wall{kind = kind, point = p_hi, normal = down, kn = spec.wall_kn, ks = 0, friction = 0}
  polling.opened(m)
  return m, lo, hi, centre, bottom, top
end

-- Sets the platens closing at `speed` each along the loading axis.
local function drive(top, bottom, dim, speed)
  local v_top, v_bottom = {}, {}
  for k = 1, dim do v_top[k], v_bottom[k] = 0, 0 end
  v_top[dim], v_bottom[dim] = -speed, speed
  top.vel, bottom.vel = v_top, v_bottom
end

-- A test's end: with opts.out, its history as CSV, the model with the
-- result (history included) as HDF5, the final state as a series with its
-- .xmf for ParaView (out_view.h5, out_view.xmf: balls, walls, cracks), and
-- its figures.
local function finish(m, r, opts, plot)
  if opts.out then
    csv.write(opts.out .. ".csv", r.columns, r.rows)
    m:vars().lab_result = copy(r)
    m:save(opts.out .. ".h5")
    m:output{path = opts.out .. "_view.h5", fields = {"all"}}:close()
    if opts.plot ~= false then plot(r, opts.out) end
  end
  m:close()
  return r
end

-- A test's peak and moduli are read from its records: an `every` as large as
-- max_steps leaves a record or two (the last at max_steps), which say
-- nothing of the peak; the test says so rather than refuse such an every.
local function few_records(r, every)
  if #r.rows < 10 then
    r.warnings[#r.warnings + 1] = string.format("only %d records in %d steps (every = %d): too few to read the peak "
                                                .. "from; lower every", #r.rows, r.steps, every)
  end
end

return {check_spec = check_spec, axis_of = axis_of, default_rate = default_rate, inertial_number = inertial_number,
        check_out_and_scale = check_out_and_scale, open = open_test, drive = drive,
        finish = finish, few_records = few_records}
