<?xml version="1.0" encoding="UTF-8"?>
<StyledLayerDescriptor xmlns="http://www.opengis.net/sld" xmlns:se="http://www.opengis.net/se" xsi:schemaLocation="http://www.opengis.net/sld http://schemas.opengis.net/sld/1.1.0/StyledLayerDescriptor.xsd" xmlns:ogc="http://www.opengis.net/ogc" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:xlink="http://www.w3.org/1999/xlink" version="1.1.0">
 <NamedLayer>
  <se:Name>batch_view_cones</se:Name>
  <UserStyle>
   <se:Name>batch_view_cones</se:Name>
   <se:FeatureTypeStyle>
    <se:Rule>
     <se:Name>view cone of a leading candidate (faded by score)</se:Name>
     <se:Description>
      <se:Title>view cone of a leading candidate (faded by score)</se:Title>
     </se:Description>
     <ogc:Filter xmlns:ogc="http://www.opengis.net/ogc">
      <ogc:Or>
       <ogc:Or>
        <ogc:PropertyIsEqualTo>
         <ogc:PropertyName>rank</ogc:PropertyName>
         <ogc:Literal>1</ogc:Literal>
        </ogc:PropertyIsEqualTo>
        <ogc:Not>
         <ogc:PropertyIsNull>
          <ogc:PropertyName>ambiguous_with</ogc:PropertyName>
         </ogc:PropertyIsNull>
        </ogc:Not>
       </ogc:Or>
       <ogc:PropertyIsGreaterThanOrEqualTo>
        <ogc:Function name="coalesce">
         <ogc:PropertyName>score</ogc:PropertyName>
         <ogc:Literal>0</ogc:Literal>
        </ogc:Function>
        <ogc:Literal>0.05</ogc:Literal>
       </ogc:PropertyIsGreaterThanOrEqualTo>
      </ogc:Or>
     </ogc:Filter>
     <se:PolygonSymbolizer>
      <se:Fill>
       <se:SvgParameter name="fill">#ffbe00</se:SvgParameter>
       <se:SvgParameter name="fill-opacity">0.27</se:SvgParameter>
      </se:Fill>
      <se:Stroke>
       <se:SvgParameter name="stroke">#b47800</se:SvgParameter>
       <se:SvgParameter name="stroke-opacity">0.63</se:SvgParameter>
       <se:SvgParameter name="stroke-width">1</se:SvgParameter>
       <se:SvgParameter name="stroke-linejoin">bevel</se:SvgParameter>
      </se:Stroke>
     </se:PolygonSymbolizer>
    </se:Rule>
   </se:FeatureTypeStyle>
  </UserStyle>
 </NamedLayer>
</StyledLayerDescriptor>
