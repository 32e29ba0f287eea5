-- The lab tests' limits and option checks on tiny specimens (a robustness
-- tester's findings): max_steps and max_strain hold whatever `every` is.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local lab = require "seixo.lab"
local joints = require "seixo.joints"

-- about 50 disks: a UCS of 1000 steps takes a few hundredths of a second
local rect = lab.specimen{dim = 2, width = 0.005, height = 0.01, radius = {0.4e-3, 0.66e-3}, seed = 3,
                          path = T.tmpname(".h5"), log = false}
local quiet = {log = false, plot = false}

-- Runs text as a script file of its own (warnings name its lines), which
-- must succeed; returns the file's name and the output.
local function run_script(text)
  local script = T.tmpname(".lua")
  local f = assert(io.open(script, "w"))
  f:write(text)
  f:close()
  local status, out = T.run(T.quote(script))
  eq(status, 0, out)
  return script:match("[^/]*$"), out
end
local function with(o)
  local t = {}
  for k, v in pairs(quiet) do t[k] = v end
  for k, v in pairs(o) do t[k] = v end
  return t
end

test("lab.ucs and lab.triaxial stop at max_steps when every is larger", function()
  -- (every = 200000 ran 200,000 steps of max_steps 1000; every = 1e9 13.6 million)
  local r = lab.ucs(rect, with{every = 200000, max_steps = 1000})
  eq(r.stopped, "max_steps")
  eq(r.steps, 1000)
  eq(#r.rows, 1)
  local few = false
  for _, w in ipairs(r.warnings) do few = few or w:find("only 1 records in 1000 steps", 1, true) ~= nil end
  check(few, "the test says its records are too few: " .. table.concat(r.warnings, "; "))
  local t = lab.triaxial(rect, with{confining = 1e5, every = 200000, max_steps = 700})
  eq(t.steps, 700)
  eq(t.stopped, "max_steps")
  -- an every that does not divide max_steps: the last record is cut short
  local s = lab.ucs(rect, with{every = 30, max_steps = 100})
  eq(s.steps, 100)
  eq(#s.rows, 4)
  eq(s.rows[4][1] - s.rows[3][1], 10)
  -- a row's step, like its time, counts from the loading's start
  eq(s.rows[4][1], s.steps)
end)

test("lab.ucs stops near max_strain when every is larger", function()
  -- (every = 200000 ran to a strain of 0.014 for max_strain 0.001)
  local r = lab.ucs(rect, with{every = 200000, max_strain = 0.001})
  eq(r.stopped, "max_strain")
  near(r.rows[#r.rows][3], 0.001, 0.05)
end)

test("lab.brazilian stops at max_steps and near max_strain when every is larger", function()
  local disk = lab.specimen{dim = 2, shape = "disk", diameter = 0.006, radius = {0.4e-3, 0.66e-3}, seed = 3,
                            path = T.tmpname(".h5"), log = false}
  local r = lab.brazilian(disk, with{every = 200000, max_steps = 900})
  eq(r.steps, 900)
  eq(r.stopped, "max_steps")
  r = lab.brazilian(disk, with{every = 200000, max_strain = 0.001})
  eq(r.stopped, "max_strain")
  near(r.rows[#r.rows][3] / r.diameter, 0.001, 0.05)
  raises(function() lab.brazilian(disk, with{max_strain = 0 / 0}) end, "lab.brazilian: max_strain must be a positive")
  -- (a string was compared with a number: "attempt to compare")
  raises(function() lab.brazilian(disk, with{post_peak = "0.5"}) end,
         "lab.brazilian: post_peak must be a number, got string '0.5' (in (0, 1))")
end)

-- about 15 disks in a periodic cell
local cell = lab.periodic.specimen{dim = 2, size = 0.004, radius = {0.4e-3, 0.66e-3}, bonds = false,
                                   path = T.tmpname(".h5"), log = false}

test("periodic.triaxial and periodic.shear stop at max_steps and near max_strain when every is larger", function()
  local r = lab.periodic.triaxial(cell, {confining = 1e5, every = 200000, max_steps = 600, log = false})
  eq(r.steps, 600)
  eq(r.stopped, "max_steps")
  r = lab.periodic.triaxial(cell, {confining = 1e5, every = 200000, max_strain = 0.001, strain_rate = 1, log = false})
  eq(r.stopped, "max_strain")
  near(r.rows[#r.rows].ea, 0.001, 0.1) -- (within the automatic timestep's drift)
  local s = lab.periodic.shear(cell, {normal = 1e5, every = 200000, max_steps = 600, log = false})
  eq(s.steps, 600)
  eq(s.stopped, "max_steps")
  raises(function() lab.periodic.triaxial(cell, {max_steps = 0 / 0, log = false}) end,
         "periodic.triaxial: max_steps must be a whole number of steps >= 1")
end)

test("joints.direct_tension stops at max_steps when every is larger; every is checked", function()
  local r = joints.direct_tension(rect, {every = 200000, max_steps = 500})
  eq(#r.rows, 1)
  -- the grips part at 7e-8 of strain a step: 500 steps, not 200,000
  check(r.rows[1][1] < 2 * 500 * 7e-8, "strain " .. r.rows[1][1])
  raises(function() joints.direct_tension(rect, {every = 0}) end,
         "joints.direct_tension: every must be a whole number of steps >= 1 (got 0)")
  raises(function() joints.direct_shear(rect, {normal_stress = 1e6, every = 0.5}) end,
         "joints.direct_shear: every must be a whole number of steps >= 1 (got 0.5)")
end)

test("a NaN or infinite stress is refused by its name", function()
  -- (confining = 0/0 said "an intermediate stress needs a 3D prism")
  raises(function() lab.triaxial(rect, with{confining = 0 / 0}) end,
         "lab.triaxial: confining must be a stress >= 0 Pa (got nan)")
  raises(function() lab.triaxial(rect, with{confining = math.huge}) end,
         "lab.triaxial: confining must be a stress >= 0 Pa (got inf)")
  raises(function() lab.triaxial(rect, with{confining = 1e5, intermediate = 0 / 0}) end,
         "lab.triaxial: intermediate must be a stress >= confining (got nan)")
  raises(function() lab.triaxial(rect, with{confining = 1e5, intermediate = math.huge}) end,
         "lab.triaxial: intermediate must be a stress >= confining (got inf)")
  -- (a NaN sigma3 said "the failure states need two different confining stresses")
  raises(function() lab.mohr_coulomb{{sigma3 = 0 / 0, sigma1 = 1e6}, {sigma3 = 1e6, sigma1 = 2e6}} end,
         "lab.mohr_coulomb: point 1's sigma3 must be a finite stress (got nan)")
  raises(function() lab.mohr_coulomb{{0, 1e6}, {1e6, math.huge}} end,
         "lab.mohr_coulomb: point 2's sigma1 must be a finite stress (got inf)")
  -- (periodic: a NaN intermediate said "an intermediate stress needs a 3D cell")
  raises(function() lab.periodic.triaxial(cell, {intermediate = 0 / 0, log = false}) end,
         "periodic.triaxial: intermediate must be a positive number (got nan)")
end)

test("a number given as a string is named as one, not as a number out of range", function()
  -- (confining = '5e6' said "confining must be a stress >= 0 Pa (got 5e6)")
  raises(function() lab.triaxial(rect, with{confining = "5e6"}) end,
         "lab.triaxial: confining must be a number, got string '5e6' (a stress >= 0 Pa)")
  raises(function() lab.triaxial(rect, with{confining = 1e5, intermediate = "2e5"}) end,
         "lab.triaxial: intermediate must be a number, got string '2e5' (a stress >= confining)")
  raises(function() lab.ucs(rect, with{strain_rate = "1"}) end,
         "lab.ucs: strain_rate must be a number, got string '1' (a positive number)")
  raises(function() lab.ucs(rect, with{every = "100"}) end,
         "lab.ucs: every must be a number, got string '100' (a whole number of steps >= 1)")
  raises(function() lab.ucs(rect, with{post_peak = "0.5"}) end, "lab.ucs: post_peak must be a number, got string '0.5'")
  raises(function() lab.ucs(rect, with{density_scale = "4"}) end,
         "lab.ucs: density_scale must be a number, got string '4' (a factor in [1, 1e6])")
  raises(function() lab.ucs(rect, with{target_ratio = true}) end,
         "lab.ucs: target_ratio must be a number, got boolean true (a ratio in (0, 1) or false)")
  raises(function() lab.series(rect, with{confining = {0, "5e6"}}) end,
         "lab.series: confining[2] must be a number, got string '5e6' (a stress >= 0 Pa)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, jobs = "2"}) end,
         "lab.series: jobs must be a number, got string '2'")
  raises(function() lab.periodic.triaxial(cell, {confining = "1e5", log = false}) end,
         "periodic.triaxial: confining must be a number, got string '1e5' (a positive number)")
  raises(function() lab.periodic.triaxial(cell, {post_peak = "0.5", log = false}) end,
         "periodic.triaxial: post_peak must be a number, got string '0.5'")
  raises(function() joints.direct_shear(rect, {normal_stress = "1e6"}) end,
         "joints.direct_shear: normal_stress must be a number, got string '1e6' (a positive number)")
end)

test("a specimen table with a missing or wrong field is refused before the test, by the field's name", function()
  -- (without wall_kn a UCS ran and gave 23 MPa instead of 154; without
  -- material or radius, or with dim = 3 on a 2D file, Lua's own errors;
  -- wall_kn = '8e10' an error of an internal m:wall call)
  local function changed(field, value)
    local s = lab.open(rect.path)
    s[field] = value
    return s
  end
  local from = ": give the table lab.specimen or lab.open returned"
  local err = raises(function() lab.ucs(changed("wall_kn", nil), quiet) end,
                     "lab.ucs: the specimen has no wall_kn (a number > 0, N/m)" .. from)
  check(err:find("^[^\n]*lab_limits%.lua:%d+: ") and not err:find("seixo/", 1, true), "at the caller's line: " .. err)
  raises(function() lab.ucs(changed("wall_kn", "8e10"), quiet) end,
         "lab.ucs: the specimen's wall_kn must be a number > 0, N/m (got string '8e10')" .. from)
  raises(function() lab.ucs(changed("material", nil), quiet) end, "lab.ucs: the specimen has no material")
  raises(function() lab.ucs({path = rect.path, dim = 2}, quiet) end, "lab.ucs: the specimen has no shape")
  raises(function() lab.ucs(changed("radius", nil), quiet) end, "lab.ucs: the specimen has no radius")
  raises(function() lab.ucs(changed("dim", 3), quiet) end,
         "lab.ucs: the specimen's dim is 3 but its file " .. rect.path .. " holds a 2D model" .. from)
  raises(function() lab.ucs(changed("shape", "prism"), quiet) end, "lab.ucs: the specimen's shape prism is not a 2D shape")
  raises(function() lab.triaxial(changed("radius", {2e-3, 1e-3}), with{confining = 1e5}) end,
         "lab.triaxial: the specimen's radius must be {rmin, rmax}, 0 < rmin <= rmax, m (got table)")
  local heavy = changed("material", lab.rock())
  heavy.material.density = "2630"
  raises(function() lab.ucs(heavy, quiet) end,
         "lab.ucs: the specimen's material must be a material table with a density > 0: its density is string '2630'")
  raises(function() lab.brazilian(changed("wall_kn", 0), quiet) end,
         "lab.brazilian: the specimen's wall_kn must be a number > 0, N/m (got 0)")
  raises(function() lab.series(changed("wall_kn", nil), with{confining = {0, 1e5}}) end,
         "lab.series: the specimen has no wall_kn")
  raises(function() lab.series(changed("dim", 3), with{confining = {0, 1e5}}) end, "lab.series: the specimen's dim is 3")
  raises(function() joints.direct_tension(changed("lo", nil), {}) end, "joints.direct_tension: the specimen has no lo "
         .. "(its box's lower corner, dim numbers, m): give the table lab.specimen, joints.jointed or lab.open returned")
  raises(function() joints.jointed(changed("material", nil), {angle = 30, path = T.tmpname(".h5")}) end,
         "joints.jointed: the specimen has no material")
  raises(function() joints.direct_shear(changed("radius", nil), {normal_stress = 1e6}) end,
         "joints.direct_shear: the specimen has no radius")
  raises(function() joints.angle_series(changed("hi", nil), {log = false}) end, "joints.angle_series: the specimen has no hi")
  local loose = lab.open(cell.path)
  loose.sigma0 = "1e5"
  raises(function() lab.periodic.triaxial(loose, {log = false}) end, "periodic.triaxial: the specimen's sigma0 must be a "
         .. "stress > 0, Pa (got string '1e5'): give the table periodic.specimen or lab.open returned")
  loose.sigma0, loose.dim = cell.sigma0, 3
  raises(function() lab.periodic.shear(loose, {log = false}) end, "periodic.shear: the specimen's dim is 3 but its file")
end)

test("lab.series checks its options and its tests' before the first test, in its own name", function()
  -- (confinement = {...} said "confining = {sigma3, ...} with two values or
  -- more", and strain_rte = 1 "lab.ucs: unknown option 'strain_rte'")
  local t = seixo.clock()
  raises(function() lab.series(rect, with{confinement = {0, 5e6}}) end,
         "lab.series: unknown option 'confinement' (valid: confine_tol, confining, density_scale, every, intermediate, "
         .. "jobs, lateral, log, max_rate, max_steps, max_strain, name, out, plot, post_peak, quasi_static, strain_rate, "
         .. "target_ratio)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, strain_rte = 1}) end,
         "lab.series: unknown option 'strain_rte'")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, strain_rate = -1}) end,
         "lab.series: strain_rate must be a positive number (got -1)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, post_peak = 2}) end,
         "lab.series: post_peak must be in (0, 1) (got 2)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, target_ratio = 2}) end,
         "lab.series: target_ratio must be a ratio in (0, 1) or false (got 2)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, strain_rate = 1, max_rate = 0.5}) end,
         "lab.series: max_rate must be a strain rate >= strain_rate = 1 1/s (got 0.5)")
  raises(function() lab.series(rect, with{confining = {0, 5e6}, out = "no/such/folder/series"}) end,
         "lab.series: cannot write no/such/folder/series_ucs.csv (out)")
  -- (it ran every test, then the fit found one confining stress)
  raises(function() lab.series(rect, with{confining = {5e6, 5e6}}) end,
         "lab.series: confining has one stress (5000000.0 Pa): the fit needs two different ones")
  check(seixo.clock() - t < 1, "refused before the tests")
end)

test("a unit warning about a value the lab passes on names the script's line", function()
  -- (confining = 10 was warned of at the line of lab.lua giving the servo its target)
  local name, out = run_script(string.format([[
local lab = require "seixo.lab"
local s = lab.open(%q)
lab.triaxial(s, {confining = 10, max_steps = 200, log = false, plot = false})
]], rect.path))
  check(out:find(name .. ":3: servo target stress 10 is outside the usual range for DEM, 1000 ... 1e+10 Pa", 1, true)
        and not out:find("seixo/", 1, true), out)
end)

test("sigma0 and the periodic tests' stresses in MPa warn, as confining does", function()
  -- (lab.specimen{sigma0 = 0.1} had no word, where confining = 10 warned)
  local name, out = run_script(string.format([[
local lab = require "seixo.lab"
lab.specimen{dim = 2, width = 0.005, height = 0.01, radius = {0.4e-3, 0.66e-3}, seed = 3, sigma0 = 0.1, path = %q, log = false}
local cell = lab.periodic.specimen{dim = 2, size = 0.004, radius = {0.4e-3, 0.66e-3}, bonds = false, sigma0 = 0.2,
                                   path = %q, log = false, max_steps = 2000}
lab.periodic.triaxial(cell, {confining = 5, log = false, max_steps = 100})
lab.periodic.shear(cell, {normal = 2e11, log = false, max_steps = 100})
lab.periodic.triaxial(cell, {confining = 5e6, log = false, max_steps = 100})
]], T.tmpname(".h5"), T.tmpname(".h5")))
  local range = " is outside the usual range for DEM, 1000 ... 1e+10 Pa (seixo's unit is Pa)"
  for _, line in ipairs{":2: lab.specimen: sigma0 0.1", ":3: periodic.specimen: sigma0 0.2",
                        ":5: periodic.triaxial: confining 5", ":6: periodic.shear: normal 2e+11"} do
    check(out:find(name .. line .. range, 1, true), out)
  end
  local _, warnings = out:gsub("seixo: warning:", "")
  eq(warnings, 4, out)
end)

test("an out that names a folder is refused: it is a path prefix", function()
  -- (out = 'dir/' wrote the hidden files dir/.csv and dir/.h5)
  local dir = T.tmpname(".d")
  os.execute("mkdir -p " .. T.quote(dir))
  local prefix = "out must be a path prefix, the files' names without their endings (.csv, .h5, ...), not a folder"
  raises(function() lab.ucs(rect, with{out = dir .. "/"}) end,
         "lab.ucs: " .. prefix .. " (got '" .. dir .. "/'): give one such as '" .. dir .. "/ucs1'")
  raises(function() lab.triaxial(rect, with{confining = 1e5, out = dir}) end,
         "lab.triaxial: " .. prefix .. " (got '" .. dir .. "'): give one such as '" .. dir .. "/triaxial1'")
  raises(function() lab.ucs(rect, with{out = "no/such/folder/"}) end, "lab.ucs: " .. prefix)
  raises(function() lab.series(rect, with{confining = {0, 1e5}, out = dir .. "/"}) end, "lab.series: " .. prefix)
  raises(function() joints.direct_shear(rect, {normal_stress = 1e6, out = dir .. "/"}) end,
         "joints.direct_shear: " .. prefix)
  raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = function() end,
                                  out = dir .. "/"} end, "lab.calibrate: " .. prefix)
  local r = lab.ucs(rect, with{out = dir .. "/ucs1", max_steps = 100})
  eq(r.steps, 100)
  check(io.open(dir .. "/ucs1.csv") and not io.open(dir .. "/.csv"), "the files in the folder, named")
  os.execute("rm -rf " .. T.quote(dir))
end)

test("a series whose fitted slope is below 1 says so in its log line, not c and phi NaN", function()
  -- (it said "Mohr-Coulomb c -nan MPa, phi -nan deg")
  local lines = {}
  local s = lab.series(rect, with{confining = {0, 1e6}, max_steps = 200, jobs = 1,
                                  log = function(line) lines[#lines + 1] = line end})
  check(s.fit.warning, "the slope of these peaks is below 1")
  local text = table.concat(lines, "\n")
  check(text:find("lab.series: Mohr-Coulomb: " .. s.fit.warning .. " (UCS of the fit", 1, true)
        and not text:find("nan", 1, true), text)
end)

test("name labels a compression test: its result and its figures' titles", function()
  local dir = T.tmpname(".d")
  os.execute("mkdir -p " .. T.quote(dir))
  local r = lab.ucs(rect, {name = "Sample 'A'", max_steps = 100, log = false, out = dir .. "/ucs"})
  eq(r.name, "Sample 'A'")
  if lab.have_gnuplot() then check(io.open(dir .. "/ucs_stress.png"), "the figure of a name with quotes") end
  os.execute("rm -rf " .. T.quote(dir))
  raises(function() lab.triaxial(rect, with{confining = 1e5, name = 5}) end,
         "lab.triaxial: name must be a string, the test's label (got number 5)")
end)

test("an error of a lab test that seixo.joints runs is at the caller's line", function()
  -- (it was at the line of joints.lua calling lab.ucs)
  local err = raises(function() joints.angle_series(rect, {test = {every = 0}, log = false}) end,
                     "lab.ucs: every must be a whole number of steps >= 1 (got 0)")
  check(err:find("^[^\n]*lab_limits%.lua:%d+: ") and not err:find("seixo/", 1, true), err)
end)

test("a log that is not false, nil or a function is refused up front, by the option's name", function()
  -- (lab.specimen{log = 5} said "attempt to call a number value" at its first line)
  raises(function() lab.specimen{dim = 2, width = 0.005, height = 0.01, radius = {0.4e-3, 0.66e-3},
                                  path = T.tmpname(".h5"), log = 5} end,
         "lab.specimen: log must be false, nil or a function (got number 5)")
  raises(function() lab.ucs(rect, {log = "quiet", max_steps = 100}) end,
         "lab.ucs: log must be false, nil or a function (got string 'quiet')")
  raises(function() lab.triaxial(rect, {confining = 1e5, log = true, max_steps = 100}) end,
         "lab.triaxial: log must be false, nil or a function (got boolean true)")
  raises(function() lab.brazilian(rect, {log = {}}) end, "lab.brazilian: log must be false, nil or a function (got table)")
  -- a series says its tests' lines itself (jobs > 1): refused before any test, not after them
  local t = seixo.clock()
  raises(function() lab.series(rect, {confining = {0, 1e5}, log = 5, max_steps = 100000}) end,
         "lab.series: log must be false, nil or a function (got number 5)")
  check(seixo.clock() - t < 1, "refused before the tests")
  raises(function() lab.periodic.specimen{dim = 2, size = 0.004, path = T.tmpname(".h5"), log = 5} end,
         "periodic.specimen: log must be false, nil or a function (got number 5)")
  raises(function() lab.periodic.triaxial(cell, {log = 5}) end, "periodic.triaxial: log must be false")
  raises(function() lab.periodic.shear(cell, {log = 5}) end, "periodic.shear: log must be false")
  -- seixo.joints: nil is silent there, and a number was called after the test had run
  raises(function() joints.direct_tension(rect, {log = 5, max_steps = 100}) end,
         "joints.direct_tension: log must be false, nil or a function (got number 5)")
  raises(function() joints.direct_shear(rect, {normal_stress = 1e6, log = 5}) end, "joints.direct_shear: log must be")
  raises(function() joints.angle_series(rect, {log = 5}) end, "joints.angle_series: log must be")
  raises(function() joints.compare{log = 5} end, "joints.compare: log must be")
  local lines = {}
  lab.ucs(rect, {max_steps = 100, plot = false, log = function(l) lines[#lines + 1] = l end})
  check(#lines > 0, "a function gets the lines")
end)

test("a compression test interrupted while loading keeps its records so far in out.csv, and says so", function()
  -- (Ctrl-C or a SIGTERM had lost the records with the test)
  local out = T.tmpname("")
  -- the interrupt comes once the test has loaded 3,000 steps (a moment
  -- after, as a Ctrl-C would), whatever the machine's speed
  local script = string.format([[
local lab = require "seixo.lab"
local load = seixo.load
seixo.load = function(...)
  local m = load(...)
  local sent
  m:on("after", function()
    if not sent then sent = os.execute("(sleep 0.2; kill -INT $PPID) &") end
  end, {every = 3000})
  return m
end
local ok, e = pcall(lab.ucs, lab.open(%q), {out = %q, log = false, plot = false, max_steps = 100000000,
                                           max_strain = 10, strain_rate = 1e-3, target_ratio = false})
print(e)]], rect.path, out)
  local shell = string.format("%s -e %s", T.quote(T.seixo), T.quote(script))
  local h = io.popen(shell .. " 2>&1")
  local said = h:read("a")
  h:close()
  local n = tonumber(said:match("interrupted.*the test's (%d+) records so far are in " .. out:gsub("%p", "%%%0") .. "%.csv"))
  check(n and n > 0, said)
  local lines = 0
  for _ in io.lines(out .. ".csv") do lines = lines + 1 end
  eq(lines, n + 1) -- (and the header)
  os.remove(out .. ".csv")
end)

T.done()
