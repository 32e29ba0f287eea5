-- Verification: the bulk modulus of a dense random packing of Hertz spheres
-- against Walton (1987) and Digby (1981) (docs/verification.md, "Granular
-- elasticity: Walton–Digby"; the full study is docs/data/walton_digby.lua).
--
-- A periodic cell of 300 spheres (radii 0.95-1.05 mm, G = 29 GPa, nu = 0.15)
-- placed as a gas, brought frictionless by the cell's servo to 1 MPa (a
-- dense packing), friction 0.3 on, then K from a small isotropic strain
-- increment (3 % of p) with the cell held and the balls relaxed, at 1 MPa
-- and at 4 MPa. Walton-Digby with the measured coordination Z (every
-- force-carrying contact, rattlers included) and porosity phi:
--   B = (1/4pi)(1/G + 1/(G + lambda)),  K_WD = (1/6) [3 Z^2 (1 - phi)^2 p / (pi^4 B^2)]^(1/3)
-- (B = (1 - nu)/(2 pi G): the (1 - nu) of the Hertz contact's modulus).
--
-- The band, K/K_WD in [0.85, 1.0], and why it is below 1 (seeds 1-10 of
-- this cell gave 0.888-0.910 at 1 MPa, mean 0.899, and 0.923-0.931 at
-- 4 MPa, mean 0.926; 1,000 balls, docs/verification.md: 0.90, 0.93, 0.93):
-- - K_WD is the affine estimate with every contact at the mean overlap. The
--   affine (Voigt) modulus of the actual network, K_aff = sum kn l^2 / 9V
--   (kn = 3/2 Fn/overlap, l the branch length), is below it: at a given
--   pressure (sum of overlap^3/2) the sum of kn (overlap^1/2) is largest
--   when all overlaps are equal, and the forces of a packing are broad.
--   Measured K_aff/K_WD 0.916-0.934 at 1 MPa, 0.958-0.964 at 4 MPa (1,000
--   balls 0.93-0.97), so 1.0 is a bound, not a fit.
-- - The balls relax from the affine motion (non-affine relaxation): K is
--   below K_aff, by 2.5-4 % here (0.966-0.975 at 1 MPa, 0.961-0.968 at 4).
-- - The lower end, 0.85, leaves about 4 % below the lowest seed; a loosely
--   prepared packing (friction from the start, Z 4.3-5.3) gives 0.80-0.87
--   and is not this test's state (Z is checked dense).
-- A wrong Hertz stiffness fails it: K goes as the contact stiffness to the
-- 2/3, so a factor 2 in the modulus moves K/K_WD by 1.59 (or 0.63), a factor
-- 2 in the effective radius by 1.26 (or 0.79), a Hertz law without its
-- 1/(1 - nu) by 0.90. Tried: the spheres' modulus x sqrt 2 (a Hertz law
-- with twice the effective radius) gives K/K_WD 1.12 and 1.16, x (1 - nu)
-- (one without its 1/(1 - nu)) 0.80 and 0.83; in this test's formula,
-- (1 - nu) dropped from B gives 1.003 and 1.029, just out, and K_aff/K_WD
-- 1.04 and 1.07, clearly out of its bound: so both ratios are asserted.
--
-- The pressure exponent d ln K / d ln p between 1 and 4 MPa: Hertz
-- (F ~ overlap^3/2) at fixed Z and phi gives 1/3; Z rising with p adds a
-- little (seeds 1-10: 0.361-0.372; 1,000 balls 0.354 from 1 to 10 MPa). A
-- contact law F ~ overlap^n gives (n - 1)/n plus that: linear springs
-- (tried) 0.011, n = 2 about 0.5. Band [1/3, 0.42].
--
-- CPU: about 5 s (22,600 steps of the frictionless stage, 4,000 of the rest).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check = T.test, T.check

local N, SEED = 300, 1
local G, NU, RHO, R0 = 29e9, 0.15, 2650, 1e-3

local m = seixo.model{dim = 3}
local function material(friction, damping)
  m:material("q", {model = "hertz", shear_modulus = G, poisson = NU, density = RHO, friction = friction,
                   damping = damping})
end
-- frictionless, local damping 0.5: the packing settles at 1 MPa in fewer
-- steps than at 0.7 (28,600 steps against 37,000 for one seed)
material(0, 0.5)
-- a gas at solid fraction 0.28 (random placement jams near 0.38)
local L = (N * 4 / 3 * math.pi * R0 ^ 3 / 0.28) ^ (1 / 3)
m:periodic{min = {0, 0, 0}, max = {L, L, L}}
m:generate{count = N, radius = {0.95 * R0, 1.05 * R0}, region = {box = {{0, 0, 0}, {L, L, L}}}, seed = SEED}

local function pressure(s) return (s[1][1] + s[2][2] + s[3][3]) / 3 end

-- the cell's servo to an isotropic p until every normal stress is within
-- tol of it and the ratio below rtol; max_rate 1e-4 strain per step (the
-- study's 2e-5 spent most of its time here)
local function servo_to(p, tol, rtol, max_steps)
  m:cell_control{xx = {stress = p}, yy = {stress = p}, zz = {stress = p}, alpha = 0.5,
                 max_rate = 1e-4 / m:timestep()}
  local start, err = m:step()
  repeat
    m:cycle(200)
    local s = m:cell_stress()
    err = 0
    for k = 1, 3 do err = math.max(err, math.abs(s[k][k] / p - 1)) end
  until (err < tol and m:ratio() < rtol) or m:step() - start >= max_steps
  return err
end

-- the cell held still, the balls relaxed
local function hold(rtol, max_steps)
  m:cell_control{xx = {rate = 0}, yy = {rate = 0}, zz = {rate = 0}}
  local start = m:step()
  repeat m:cycle(100) until m:ratio() < rtol or m:step() - start >= max_steps
  return m:ratio()
end

-- coordination (force-carrying contacts, rattlers included), porosity, and
-- the affine bulk modulus of the contact network
local function network()
  local cell = m:periodic()
  local V = cell.size[1] * cell.size[2] * cell.size[3]
  local n, sum = 0, 0
  for c in m:contacts{kind = "ball-ball"} do
    if c.fn > 0 then
      n = n + 1
      local l = c.a.radius + c.b.radius - c.overlap
      sum = sum + 1.5 * c.fn / c.overlap * l * l
    end
  end
  return 2 * n / m:ball_count(), 1 - m:sum("volume") / V, sum / (9 * V)
end

local function walton_digby(Z, phi, p)
  local lambda = 2 * G * NU / (1 - 2 * NU)
  local B = (1 / (4 * math.pi)) * (1 / G + 1 / (G + lambda))
  return (1 / 6) * (3 * Z ^ 2 * (1 - phi) ^ 2 * p / (math.pi ^ 4 * B ^ 2)) ^ (1 / 3)
end

-- K at pressure p: servo there with friction, relax, then compress every
-- axis by eps over 1,000 steps (eps ~ p^2/3: dp about 3 % of p), relax
local function bulk_modulus(p)
  local err = servo_to(p, 0.002, 1e-4, 50000)
  local r0 = hold(1e-6, 50000)
  local s0, L0 = m:cell_stress(), m:periodic().size
  local Z, phi, Kaff = network()
  local eps = 5e-6 * (p / 1e5) ^ (2 / 3)
  local rate = -eps / (1000 * m:timestep())
  m:cell_control{xx = {rate = rate}, yy = {rate = rate}, zz = {rate = rate}}
  m:cycle(1000)
  local r1 = hold(1e-6, 50000)
  local s1, L1 = m:cell_stress(), m:periodic().size
  local dev = 3 - L1[1] / L0[1] - L1[2] / L0[2] - L1[3] / L0[3]
  local dp = pressure(s1) - pressure(s0)
  local pm = pressure(s0) + dp / 2
  local r = {p = pm, Z = Z, phi = phi, K = dp / dev, Kaff = Kaff, Kwd = walton_digby(Z, phi, pm),
             err = err, ratio = math.max(r0, r1)}
  print(string.format("p %.4g Pa: Z %.3f, porosity %.4f, K %.4g Pa, K_WD %.4g, K/K_WD %.3f, K_aff/K_WD %.3f, K/K_aff %.3f",
                      r.p, Z, phi, r.K, r.Kwd, r.K / r.Kwd, Kaff / r.Kwd, r.K / Kaff))
  return r
end

local err = servo_to(1e6, 0.01, 1e-3, 100000)
print(string.format("frictionless stage: %d steps, stress within %.2g of 1 MPa, ratio %.2g", m:step(), err, m:ratio()))
material(0.3, 0.7)
local at1 = bulk_modulus(1e6)
local at4 = bulk_modulus(4e6)

for _, r in ipairs{at1, at4} do
  local what = string.format(" at %.3g MPa", r.p / 1e6)
  test("a dense state, at rest" .. what, function()
    check(r.err < 0.002, "servo error " .. r.err)
    check(r.ratio < 1e-5, "ratio " .. r.ratio)
    check(r.Z > 5.8 and r.Z < 6.8, "Z " .. r.Z)
    check(r.phi > 0.34 and r.phi < 0.38, "porosity " .. r.phi)
  end)
  test("K/K_WD in [0.85, 1]" .. what, function()
    check(r.K / r.Kwd >= 0.85 and r.K / r.Kwd <= 1, string.format("K/K_WD %.4f", r.K / r.Kwd))
  end)
  test("K <= K_aff <= K_WD, each within 10 %" .. what, function()
    check(r.K / r.Kaff >= 0.9 and r.K / r.Kaff <= 1, string.format("K/K_aff %.4f", r.K / r.Kaff))
    check(r.Kaff / r.Kwd >= 0.9 and r.Kaff / r.Kwd <= 1, string.format("K_aff/K_WD %.4f", r.Kaff / r.Kwd))
  end)
end

test("d ln K / d ln p from 1 to 4 MPa in [1/3, 0.42]", function()
  local x = math.log(at4.K / at1.K) / math.log(at4.p / at1.p)
  print(string.format("d ln K / d ln p = %.3f", x))
  check(x >= 1 / 3 and x <= 0.42, string.format("%.4f", x))
end)

T.done()
