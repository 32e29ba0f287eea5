-- seixo.lab.mohr_coulomb: the Mohr-Coulomb envelope of failure states
-- (lab.mohr_coulomb), a series' strength parameters.
local check = require "seixo.check"
local mohr_coulomb = {}

--- Fits the Mohr-Coulomb criterion sigma1 = UCS + N sigma3 to the failure
--- states {{sigma3 =, sigma1 =}, ...} by least squares; N = (1 + sin phi) /
--- (1 - sin phi) and UCS = 2 c sqrt(N). Returns {c =, phi = (degrees), N =,
--- intercept =, r2 =, rms =, points =}.
function mohr_coulomb.fit(points)
  if type(points) ~= "table" or #points < 2 then error("lab.mohr_coulomb: two failure states or more expected", 2) end
  local n, sx, sy, sxx, sxy = #points, 0, 0, 0, 0
  for i, p in ipairs(points) do
    local x, y = p.sigma3 or p[1], p.sigma1 or p[2]
    if type(x) ~= "number" or type(y) ~= "number" then
      error(string.format("lab.mohr_coulomb: point %d needs sigma3 and sigma1 numbers", i), 2)
    end
    -- (a NaN, from a failed test or fit, made the sums NaN and was reported
    -- as "two different confining stresses" needed)
    for _, v in ipairs{{"sigma3", x}, {"sigma1", y}} do
      if not (v[2] > -math.huge and v[2] < math.huge) then
        error(string.format("lab.mohr_coulomb: point %d's %s must be a finite stress (got %s)", i, v[1],
                            check.show(v[2])), 2)
      end
    end
    sx, sy, sxx, sxy = sx + x, sy + y, sxx + x * x, sxy + x * y
  end
  local den = n * sxx - sx * sx
  if not (den > 0) then error("lab.mohr_coulomb: the failure states need two different confining stresses", 2) end
  local slope = (n * sxy - sx * sy) / den
  local intercept = (sy - slope * sx) / n
  local mean, ss_tot, ss_res = sy / n, 0, 0
  for _, p in ipairs(points) do
    local x, y = p.sigma3 or p[1], p.sigma1 or p[2]
    ss_tot = ss_tot + (y - mean) ^ 2
    ss_res = ss_res + (y - (intercept + slope * x)) ^ 2
  end
  local fit = {N = slope, intercept = intercept, points = n, rms = math.sqrt(ss_res / n),
               r2 = ss_tot > 0 and 1 - ss_res / ss_tot or 1}
  if slope >= 1 then
    fit.phi = math.deg(math.asin((slope - 1) / (slope + 1)))
    fit.c = intercept / (2 * math.sqrt(slope))
  else -- strength falling with confinement: no Mohr-Coulomb envelope
    fit.phi, fit.c = 0 / 0, 0 / 0
    fit.warning = string.format("the fitted slope %.3g is below 1: no friction angle", slope)
  end
  return fit
end

return mohr_coulomb
